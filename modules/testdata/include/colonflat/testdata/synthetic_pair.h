#pragma once
// A synthetic supine/prone pair with known correspondence, for tests and benchmarks (test-support
// library colonflat_testdata_register; each scan's flat.vtp is written by flatten's
// flat_to_polydata, the same writer as `colonflat flatten`): one tube
// (calibre changes, crescent haustral folds, polyps as bumps) given in material coordinates
// (sigma = mm along the supine centre line, phi = angle around), placed twice: supine, and prone
// with its middle shifted sideways, the wall slid along the colon, optionally rotated around the
// centre line and with the flat x running from the other end. Every wall vertex knows its
// material coordinates, so the registration error of any vertex is known.
#include <cstdint>
#include <filesystem>
#include <utility>
#include <vector>

#include "colonflat/register/scan.h"

namespace cf {

struct SyntheticPairOptions {
  double length_mm = 500;    // mm, supine centre-line length
  double radius_mm = 20;     // mm, mean lumen radius
  double spacing_mm = 1.5;   // mm, vertex spacing of the supine grid (prone: 1.1 x)
  std::uint64_t seed = 1;    // fold and polyp placement
  double shift_mm = 40;      // mm, sideways displacement of the prone middle
  double slide_mm = 15;      // mm, amplitude of the prone wall's slide along the colon
  double twist_deg = 0;      // degrees, rotation of the prone wall around its centre line
  bool centreline = true;    // flat.vtp carries centreline_mm and end labels (contract 1)
  bool reverse_prone = false;// prone flat x (and centreline_mm) starts at the other end
  int polyps = 6;            // polyps 6-12 mm, seen in both scans
  int extra_candidates = 1;  // false candidates per scan seen in that scan only
  // Stretches [from, to) of material sigma (mm) left out of that scan's segmentation (a collapse,
  // a fully tagged stretch, the rectum cut short by the catheter): the colon is then several bands,
  // each with its own centreline_mm from its x0 end, as flatten writes them.
  std::vector<std::pair<double, double>> supine_removed, prone_removed;
  bool shuffle_pieces = false;  // FlatSegments "order" of the middle bands reversed
};

struct SyntheticPolyp {
  int id = 0;
  double sigma_mm = 0, phi_rad = 0, size_mm = 0;
  Eigen::Vector3d supine_lps{0, 0, 0}, prone_lps{0, 0, 0};
  bool in_supine = true, in_prone = true;  // not in a stretch left out of that scan (then no candidate)
};

struct SyntheticPair {
  ColonScan supine, prone;
  std::vector<SyntheticPolyp> polyps;  // candidate ids 1..n in both scans; extras get ids 100+
  // Material coordinates per flat vertex of each scan.
  std::vector<double> supine_sigma, supine_phi, prone_sigma, prone_phi;
};

SyntheticPair make_synthetic_pair(const SyntheticPairOptions& opts);

// Writes a scan as a run directory (flat.vtp, candidates.json, run_report.json), atomically.
void write_run_dir(const ColonScan& scan, const std::filesystem::path& dir);

}  // namespace cf
