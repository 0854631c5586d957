// phantom.json: everything a user needs to interpret the case.
#include "phantom_description.h"

#include <algorithm>

#include "colonflat/core/tool.h"

namespace cf::phantom_detail {
namespace {

nlohmann::json colon_json(const Model& md, const VolumeCounts& counts, bool collapsed_option) {
  const Path& P = md.path;
  const Grid& g = md.g;
  const double voxel_ml = g.sp[0] * g.sp[1] * g.sp[2] / 1000.0;
  nlohmann::json segs = nlohmann::json::array();
  for (int sgi = 0; sgi < 6; ++sgi) {
    double a = P.length, b = 0;
    for (std::size_t i = 0; i < P.p.size(); ++i)
      if (P.seg[i] == sgi) a = std::min(a, P.arc[i]), b = std::max(b, P.arc[i]);
    segs.push_back({{"name", kSegmentNames[sgi]}, {"start_mm", a}, {"end_mm", b}});
  }
  nlohmann::json pools = nlohmann::json::array();
  for (const Pool& p : md.pools)
    pools.push_back({{"segment_start_mm", p.s0}, {"segment_end_mm", p.s1}, {"level_y_lps_mm", p.level_y},
                     {"seed_lps_mm", {p.seed.x(), p.seed.y(), p.seed.z()}}, {"hu", p.hu},
                     {"volume_ml", double(p.voxels) * voxel_ml}});
  nlohmann::json stretches = nlohmann::json::array();
  for (const TaggedStretch& t : md.stretches)
    stretches.push_back({{"start_mm", t.s0}, {"end_mm", t.s1}, {"hu", t.hu}, {"volume_ml", double(t.voxels) * voxel_ml},
                         {"neck_length_mm", 16}});
  nlohmann::json collapsed = nullptr;
  if (collapsed_option && !md.collapses.empty())
    collapsed = {{"center_mm", md.collapses.front().s}, {"length_mm", md.collapses.front().len}};
  return {{"length_mm", P.arc.back()},
          {"segments", segs},
          {"radius_range_mm", {*std::min_element(P.r.begin(), P.r.end()), *std::max_element(P.r.begin(), P.r.end())}},
          {"folds", md.folds.size()},
          {"wall_thickness_mm", md.wall},
          {"lumen_volume_ml", double(counts.lumen) * voxel_ml},
          {"fluid_volume_ml", double(counts.fluid) * voxel_ml},
          {"collapsed", collapsed},
          {"fluid_pools", pools},
          {"fully_tagged_stretches", stretches}};
}

nlohmann::json extras_json(const Model& md, const VolumeCounts& counts) {
  const Grid& g = md.g;
  const double voxel_ml = g.sp[0] * g.sp[1] * g.sp[2] / 1000.0;
  nlohmann::json loops = nlohmann::json::array();
  for (const BowelLoop& l : md.bowel)
    loops.push_back({{"radius_mm", l.r}, {"length_mm", 2.0 * double(l.pts.size() - 1)}, {"hu", l.hu}, {"has_gas", l.gas_level > -1e8}});
  nlohmann::json e = {{"small_bowel_loops", loops},
                      {"small_bowel_contrast_ml", double(counts.by_label[kTruthBowelContrast]) * voxel_ml},
                      {"small_bowel_gas_ml", double(counts.by_label[kTruthBowelGas]) * voxel_ml},
                      {"bladder_ml", double(counts.by_label[kTruthBladder]) * voxel_ml},
                      {"rectal_tube_ml", double(counts.by_label[kTruthTube]) * voxel_ml},
                      {"enhanced_vessel_ml", double(counts.by_label[kTruthVessel]) * voxel_ml}};
  if (md.bladder) e["bladder"] = {{"center_lps_mm", {md.bladder_c.x(), md.bladder_c.y(), md.bladder_c.z()}},
                                  {"radii_mm", {md.bladder_r.x(), md.bladder_r.y(), md.bladder_r.z()}}};
  return e;
}

}  // namespace

nlohmann::json describe_phantom(const PhantomOptions& o, const Model& md, const VolumeCounts& counts) {
  const Grid& g = md.g;
  nlohmann::json gas = nlohmann::json::array();
  for (const auto& [c, r] : md.gas) gas.push_back({{"center_lps_mm", {c.x(), c.y(), c.z()}}, {"radii_mm", {r.x(), r.y(), r.z()}}});
  const double blur = o.blur_mm > 0 ? o.blur_mm : std::max(0.45, 0.6 * std::min(g.sp[0], g.sp[1]));
  return {
      {"generator", "colonflat phantom"},
      {"version", colonflat_version()},
      {"seed", o.seed},
      {"size", o.size},
      {"units", "mm"},
      {"coordinate_system", "LPS"},
      {"patient_position", md.gravity > 0 ? "supine (posterior, +y, is gravity-dependent)" : "prone (anterior, -y, is gravity-dependent)"},
      {"dicom_patient_position", md.gravity > 0 ? "HFS" : "HFP"},
      {"volume", {{"dimensions", {g.n[0], g.n[1], g.n[2]}}, {"spacing_mm", {g.sp[0], g.sp[1], g.sp[2]}},
                  {"origin_lps_mm", {g.org[0], g.org[1], g.org[2]}}, {"direction", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}}},
      {"options", {{"collapsed_segment", o.collapsed_segment}, {"tagged_fluid", o.tagged_fluid}, {"polyps", o.polyps},
                   {"topological_noise", o.topological_noise}, {"noise_hu", o.noise_hu}, {"blur_mm", blur},
                   {"position", o.position}, {"fully_tagged_segments", o.fully_tagged_segments},
                   {"oral_contrast", o.oral_contrast}, {"excreted_contrast", o.excreted_contrast},
                   {"enhanced_vessels", o.enhanced_vessels}, {"rectal_tube", o.rectal_tube}}},
      {"colon", colon_json(md, counts, o.collapsed_segment)},
      {"other_gas", gas},
      {"extra_anatomy", extras_json(md, counts)},
      {"labels", {{"0", "other"}, {"1", "colon gas"}, {"2", "colon tagged fluid"}, {"3", "small-bowel oral contrast"},
                  {"4", "small-bowel gas"}, {"5", "bladder (urine, excreted contrast)"}, {"6", "rectal tube"},
                  {"7", "other gas"}, {"8", "enhanced vessel"}}},
      {"hu", {{"air", -1000}, {"lung", -860}, {"fat", -100}, {"visceral_fat", -90}, {"muscle", 50}, {"colon_wall", 40},
              {"polyp", 45}, {"liver", 60}, {"kidney", 35}, {"spine", 350}, {"cortical_bone", 900}, {"urine", 10},
              {"excreted_contrast", 900}, {"rectal_tube", 150}, {"aorta", 260}}},
      {"files", {{"ct", "ct.nrrd (or dicom/ with --format dicom)"}, {"lumen_mask", "lumen_mask.nrrd"},
                 {"labels", "labels.nrrd"}, {"polyps", "polyps.json"}, {"centerline", "centerline.json"},
                 {"noise_sites", "noise_sites.json"}}}};
}

}  // namespace cf::phantom_detail
