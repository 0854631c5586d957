#pragma once
// segment_bench --painted's link log (issue 25, session 14; docs/segment.md step 6): with
// COLONFLAT_SEGMENT_LINKS=FILE set, segment_colon reports every contact its linking step judged
// (SegmentStats::links) and dump_links appends each, with its ground-truth label, to FILE.
#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>

#include "colonflat/phantom/mask_phantom.h"
#include "colonflat/segment/segment.h"

namespace {

// COLONFLAT_SEGMENT_LINKS=FILE: every link the segmentation judged, with the truth label (majority of
// the labels at the candidate's sample voxels) appended to FILE as one JSON object per line.
void dump_links(const cf::SegmentStats& st, const cf::MaskPhantom& p, int seed, const std::string& name) {
  const char* file = std::getenv("COLONFLAT_SEGMENT_LINKS");
  if (!file || !*file) return;
  std::ofstream out(file, std::ios::app);
  const cf::MaskImage* lab = p.phantom.labels.GetPointer();
  auto truth = [&](const nlohmann::json& samples) {
    int votes[10] = {0};
    for (const auto& s : samples) {
      cf::MaskImage::PointType pt;
      for (int d = 0; d < 3; ++d) pt[d] = s[d].get<double>();
      cf::MaskImage::IndexType ix;
      if (lab->TransformPhysicalPointToIndex(pt, ix)) ++votes[std::min(9, int(lab->GetPixel(ix)))];
    }
    return int(std::max_element(votes, votes + 10) - votes);
  };
  for (nlohmann::json j : st.links) {
    j["seed"] = seed;
    j["case"] = name;
    j["truth"] = truth(j.value("cand_samples", nlohmann::json::array()));
    if (j.contains("seg_samples")) j["seg_truth"] = truth(j["seg_samples"]);
    j.erase("cand_samples");
    j.erase("seg_samples");
    out << j.dump() << "\n";
  }
}

}  // namespace
