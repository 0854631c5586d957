#pragma once
// Supine-prone registration of two flattened colons (docs/register.md).
//
//   cf::ColonScan sup = cf::read_run_dir("supine"), pro = cf::read_run_dir("prone");
//   cf::ColonRegistration reg(sup, pro, cf::RegisterOptions{});
//   reg.run();                                         // coordinates, length, twist, vertices, candidates
//   Eigen::Vector3d q = reg.map_lps(p, cf::Direction::kSupineToProne);
//
// Steps: (1) per scan, colon coordinates (s along, theta around; profile.h); (2) orientation and
// length alignment by dynamic time warping of fold / calibre / curvature profiles; (3) residual
// rotation around the colon from the wall relief; (4) per-vertex correspondence in both
// directions (nearest vertex in (s, r theta) of the other scan); (5) candidate matching.
// The two scans are borrowed: they must outlive the registration.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "colonflat/register/align.h"
#include "colonflat/register/pieces.h"
#include "colonflat/register/profile.h"
#include "colonflat/register/scan.h"
#include "colonflat/register/support.h"

namespace cf {

struct RegisterOptions {
  ProfileOptions profile;
  AlignOptions align;
  TwistOptions twist;
  std::string orientation = "auto";  // "auto" (try both when the rectal end is not labelled), "same", "reverse"
  double match_along_mm = 30;        // mm; largest distance along the colon of a candidate pair
  double match_around_deg = 45;      // degrees; largest angle around the colon of a pair
  double match_size_ratio = 2.0;     // largest size ratio of a pair (larger / smaller)
  double min_place_reach_mm = 3;     // mm; a candidate's other places on the course (locations()) lie this much,
                                     //   or half its size if larger, beyond its nearest wall vertex: the wall a
                                     //   polyp stands on reaches its radius around it (3 mm: half the smallest
                                     //   polyp reported, 6 mm)
  PieceOptions pieces;               // colons with centreline_mm: laid out piece by piece (pieces.h)
  double own_axis_off_radii = 0.5;   // colon radii; where the common profile's centre lies this far across
                                     //   from a candidate's own piece's centre line (walls of other
                                     //   stretches laid at that s: a neck), its angle is taken about its own
                                     //   piece's (a centre line within half a radius is inside the lumen)
  LandmarkOptions landmarks;
  double support_radius_mm = 100;    // mm; centre points farther apart after the shift do not support the map
  double max_unsupported_mm = 10;    // mm; a candidate farther along from a supported bin is never paired
  double match_3d_mm = 120;          // mm; largest LPS distance of a pair after the rigid shift (organ motion)
  double anchor_along_mm = 10;       // a pair this close (along, around), alone within the match limits,
  double anchor_around_deg = 30;     //   becomes an anchor of a second alignment pass
  double anchor_tolerance_mm = 6;    // mm; the second pass passes this close to each anchor
  double landmark_tolerance_mm = 60; // mm; a shared landmark counts when the map agrees with it this well
};

enum class Direction { kSupineToProne, kProneToSupine };

struct CandidateMatch {
  int supine_id = 0, prone_id = 0;
  double along_mm = 0;      // |s_prone - map(s_supine)| on the length map (never the common s: it misses the wall slide)
  double around_deg = 0;    // |theta difference| after registration
  double size_ratio = 1;    // larger / smaller (1 when a size is unknown)
  double score = 0;         // raised: 1 - (1 - score_supine)(1 - score_prone)
  double distance_3d_mm = 0;  // LPS distance after the rigid shift between the scans
  double supine_gap_mm = 0, prone_gap_mm = 0;  // mm along to the nearest supported bin (0: supported)
  double anchor_mm = 0;     // mm along (supine) to the nearest shared landmark or other anchor pair
  bool unique = true;       // no other partner within the match limits for either candidate
  // The places of the two candidates the pair was matched at (locations(): one of each candidate's
  // places on its course); everything shown for the pair uses them (candidate_place()).
  double supine_s_mm = std::numeric_limits<double>::quiet_NaN(), supine_theta = std::numeric_limits<double>::quiet_NaN();
  double prone_s_mm = std::numeric_limits<double>::quiet_NaN(), prone_theta = std::numeric_limits<double>::quiet_NaN();
};

// Where an unpaired candidate is shown and mapped: its first place on the course (locations()) with
// support along, else its nearest.
struct CandidatePlace {
  int id = 0;
  double s_mm = std::numeric_limits<double>::quiet_NaN(), theta = std::numeric_limits<double>::quiet_NaN();
};

struct CandidateMatching {
  std::vector<CandidateMatch> pairs;
  std::vector<int> supine_only, prone_only;  // candidate ids
  std::vector<int> supine_unaligned, prone_unaligned;  // of those, ids where the alignment has no support
  std::vector<CandidatePlace> supine_shown, prone_shown;  // of supine_only / prone_only (same order): where shown
  // (s, theta) of candidate `id` of the supine (or prone) list: its pair's place, else its shown place.
  // Post: NaN when the id is in neither.
  std::pair<double, double> place(int id, bool supine) const;
};

class ColonRegistration {
 public:
  ColonRegistration(const ColonScan& supine, const ColonScan& prone, RegisterOptions opts = {});
  ~ColonRegistration();
  void run();  // all steps below, in order

  void compute_coordinates();   // (1) + orientation choice (2)
  void align_along();           // (2) with the anchors found so far
  void assess_support();        // landmarks, shared landmarks, support of the length map
  void anchor_on_candidates();  // unique close candidate pairs become anchors (returns via anchors())
  void align_around();          // (3)
  void correspond_vertices();   // (4)
  void match_candidates();      // (5) the scans' own candidates
  // Matches any two candidate lists (e.g. ground-truth polyps) with the registration's map.
  CandidateMatching match(const std::vector<ScanCandidate>& supine, const std::vector<ScanCandidate>& prone) const;

  // mm along from a scan's s to the nearest supported bin (0 = supported; infinity: none).
  double support_gap_mm(bool supine_scan, double s) const;
  // Position of a scan's point (s, theta) in the other scan.
  void map_coordinates(Direction d, double s, double theta, double& s_out, double& theta_out) const;
  // Nearest wall vertex of the target scan to the image of a point (-1 when not registered).
  int map_vertex(Direction d, double s, double theta) const;
  // Nearest registered wall vertex of the supine (or prone) scan to its own (s, theta); -1 if none.
  int vertex_at(bool supine_scan, double s, double theta) const;
  // An LPS point of one scan to the other: nearest wall vertex, its (s, theta), mapped, the
  // target's wall vertex there; returns its LPS position (NaN when the point is not registered).
  Eigen::Vector3d map_lps(const Eigen::Vector3d& p, Direction d) const;
  // (s, theta) where candidate `id` of the scan `from` is shown and mapped: the place its pair was
  // matched at (CandidateMatch::supine_s_mm ...); unpaired, its first place (locations()) with support
  // along, else its nearest (locate()). The same place decides the "not aligned" lists. Read from
  // matching() (CandidateMatching::place; kept by match_candidates(), no point query).
  // Post: NaN when the scan has no candidate `id` or the place is not registered.
  std::pair<double, double> candidate_place(int id, Direction from) const;
  // The other scan's LPS position of candidate `id` of the scan `d` maps from: its candidate_place()
  // mapped, the target's wall vertex there (NaN when not registered).
  Eigen::Vector3d map_candidate(int id, Direction d) const;
  // The same for candidate `id` of a matching `m` of any two lists (match()): m.place() mapped, the
  // target's wall vertex there (NaN when not registered or not in `m`).
  Eigen::Vector3d map_place(const CandidateMatching& m, int id, Direction d) const;
  // True when a candidate at this LPS point of one scan, or its image in the other, lies on a stretch
  // held at a neck (pieces.h): never paired there.
  bool held_at_neck(const Eigen::Vector3d& p, Direction from) const;
  // (s, theta) of an LPS point of a scan: s of its nearest wall vertex, theta of the point about
  // the centre line there (NaN when that vertex is not registered).
  std::pair<double, double> locate(const Eigen::Vector3d& p, Direction from) const;
  // locate() first, then every other place of the point on the colon's course: where the course passes
  // it more than once (a neck with a long branch inserted into the course before it, walls of two loops
  // touching) the wall within `reach_mm` beyond the nearest vertex's distance belongs to several
  // stretches; each is represented by its vertex nearest to p that lies more than match_along_mm along
  // from the places already found (nearest first). Each angle is about the point's own piece's centre
  // line where the profile's centre lies own_axis_off_radii or more across from it (a neck; else as
  // locate()). Post: size >= 1; entries NaN when not registered.
  std::vector<std::pair<double, double>> locations(const Eigen::Vector3d& p, Direction from, double reach_mm) const;

  const ScanCoordinates& supine_coordinates() const { return sup_; }
  const ScanCoordinates& prone_coordinates() const { return pro_; }
  const LengthAlignment& length() const { return length_; }
  const std::vector<double>& twist_rad() const { return twist_; }  // per supine profile bin
  const std::vector<int>& supine_to_prone() const { return sup_to_pro_; }
  const std::vector<int>& prone_to_supine() const { return pro_to_sup_; }
  const CandidateMatching& matching() const { return matching_; }
  const ColonScan& supine() const { return supine_; }
  const ColonScan& prone() const { return prone_; }
  bool prone_reversed() const { return pro_.reversed; }
  bool piecewise() const { return piecewise_; }
  const RegisterOptions& options() const { return opts_; }
  const PieceLayout& pieces() const { return layout_; }
  const AlignmentSupport& support() const { return support_; }
  const std::vector<AlignAnchor>& anchors() const { return anchors_; }
  const std::vector<SharedLandmark>& shared_landmarks() const { return shared_; }
  const Eigen::Vector3d& prone_to_supine_shift() const { return b_to_a_; }
  nlohmann::json summary() const;  // the JSON written to registration.json (without inputs)
  nlohmann::json pieces_json() const;     // the layout of both scans' pieces
  nlohmann::json landmarks_json() const;  // landmarks per scan, shared ones, anchors

 private:
  struct Index;
  const ColonScan& supine_;
  const ColonScan& prone_;
  RegisterOptions opts_;
  ScanCoordinates sup_, pro_;
  LengthAlignment length_;
  bool piecewise_ = false;
  PieceLayout layout_;
  Eigen::Vector3d b_to_a_{0, 0, 0};
  std::vector<Landmark> sup_marks_, pro_marks_;
  std::vector<SharedLandmark> shared_;
  std::vector<AlignAnchor> anchors_;
  AlignmentSupport support_;
  std::vector<double> twist_;
  int twist_windows_ = 0;
  std::vector<int> sup_to_pro_, pro_to_sup_;
  std::vector<char> sup_held_, pro_held_;  // per vertex: held at a neck (pieces.h held_at_neck)
  struct Place {
    double s, theta, gap;  // gap: mm along to supported alignment (infinite: held at a neck)
  };
  std::vector<Place> places(const ScanCandidate& c, Direction from) const;
  size_t shown_place(const std::vector<Place>& pl) const;  // first supported place, else 0
  // The candidates of `c` not `used`: their ids, those without support, and where each is shown.
  void list_unpaired(const std::vector<ScanCandidate>& c, const std::vector<std::vector<Place>>& pl,
                     const std::vector<bool>& used, std::vector<int>& only, std::vector<int>& unaligned,
                     std::vector<CandidatePlace>& shown) const;
  bool pair_at_places(const ScanCandidate& a, const std::vector<Place>& pa, const ScanCandidate& b,
                      const std::vector<Place>& pb, CandidateMatch& best, double& cost) const;
  CandidateMatching matching_;
  std::unique_ptr<Index> sup_index_, pro_index_;
  nlohmann::json timing_ = nlohmann::json::object();
};

}  // namespace cf
