// Surfaces made outside the project (issue 29): the real lumen mask turned into a surface by VTK's
// discrete marching cubes (not reconstruct), written by VTK's writers or as OFF with inward
// normals, runs `colonflat run --from denoise` end to end with the figures of the outward surface
// (genus, loops cut, bands, coverage, candidates), and the reports say what was reversed. A patch of
// flipped faces is turned back; a non-orientable surface is refused with the reason.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "colonflat/testdata/foreign_surface.h"
#include "colonflat/testdata/synthetic.h"
#include "colonflat/testing/command.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

const fs::path kMask = fs::path(COLONFLAT_SHARED_DIR) / "real" / "ctc_lumen_mask_a.nii.gz";

// What a run shows a user.
struct Figures {
  int genus_before = -1, genus_after = -1;
  std::size_t loops = 0, bands = 0, candidates = 0;
  double coverage = 0;
  nlohmann::json denoise_orientation, flatten_orientation;
  std::string err;
};

const nlohmann::json& stage_result(const nlohmann::json& report, const std::string& name) {
  for (const auto& s : report["stages"])
    if (s["stage"] == name) return s["result"];
  throw std::runtime_error("no stage " + name + " in the run report");
}

Figures run_from_denoise(const fs::path& in, const fs::path& out, bool snapshots) {
  std::vector<std::string> args = {"run", "--from", "denoise", in.string(), "-o", out.string()};
  if (!snapshots) args.insert(args.end(), {"--set", "render.snapshots=false"});
  const auto r = testing::run_colonflat(args);
  Figures f;
  f.err = r.err;
  EXPECT_EQ(r.code, 0) << in << ": " << r.err;
  if (r.code != 0) return f;
  std::ifstream s(out / "run_report.json");
  const nlohmann::json j = nlohmann::json::parse(s);
  const auto& d = stage_result(j, "denoise");
  f.genus_before = d["genus_before"].get<int>();
  f.genus_after = d["genus_after"].get<int>();
  f.loops = d["totals"]["loops"].get<std::size_t>();
  f.denoise_orientation = d["orientation"];
  const auto& fl = stage_result(j, "flatten");
  f.bands = fl["segment_count"].get<std::size_t>();
  f.coverage = fl["coverage"]["fraction_shown"].get<double>();
  f.flatten_orientation = fl["orientation"];
  f.candidates = stage_result(j, "render")["candidates"].get<std::size_t>();
  return f;
}

void expect_same_figures(const Figures& out, const Figures& in, const std::string& what) {
  EXPECT_EQ(in.genus_before, out.genus_before) << what;
  EXPECT_EQ(in.genus_after, 0) << what;
  EXPECT_EQ(in.loops, out.loops) << what;
  EXPECT_EQ(in.bands, out.bands) << what;
  // Inward and outward are read by the same reader (the coordinates are identical), and the reader
  // turns the inward faces back into the outward ones: the maps are the same to rounding.
  EXPECT_NEAR(in.coverage, out.coverage, 1e-9) << what;
  EXPECT_EQ(in.candidates, out.candidates) << what;
}

// The inward run says, in its report and in one progress line, that component 0 was reversed;
// the outward one reverses nothing; flatten then gets an outward surface.
void expect_reversal_reported(const Figures& out, const Figures& in, const std::string& what) {
  EXPECT_EQ(out.denoise_orientation["reversed_components"], 0) << what;
  EXPECT_GE(in.denoise_orientation["reversed_components"].get<int>(), 1) << what;
  EXPECT_EQ(in.flatten_orientation["reversed_components"], 0) << what;
  const std::string note = in.denoise_orientation["notes"][0].get<std::string>();
  EXPECT_EQ(note.rfind("component 0 (", 0), 0u) << what << ": " << note;
  EXPECT_NE(note.find("normals pointed into the lumen; reversed"), std::string::npos) << what << ": " << note;
  EXPECT_NE(in.err.find("denoise: surface: " + note), std::string::npos) << what;
  EXPECT_EQ(in.err.find("large enough"), std::string::npos) << what;
}

// The full real mask (marching cubes: ~1.4 M faces), VTP with inward normals: the same figures as
// the outward VTP, end to end (snapshots included), and the reversal reported.
TEST(ForeignSurface, FullRealMaskInwardRunsLikeOutward) {
  if (!fs::exists(kMask)) GTEST_SKIP() << kMask << " missing";
  testing::TempDir tmp;
  const TriangleList outward = testing::foreign_marching_cubes(kMask, 1);
  testing::write_foreign(outward, tmp / "outward.vtp");
  testing::write_foreign(testing::reversed_faces(outward), tmp / "inward.vtp");
  const Figures out = run_from_denoise(tmp / "outward.vtp", tmp / "run_out", true);
  const Figures in = run_from_denoise(tmp / "inward.vtp", tmp / "run_in", true);
  std::cout << "full mask: " << outward.triangles.size() << " faces, genus " << out.genus_before << ", loops "
            << out.loops << " / " << in.loops << ", bands " << out.bands << " / " << in.bands << ", coverage "
            << out.coverage << " / " << in.coverage << ", candidates " << out.candidates << " / " << in.candidates
            << " (outward / inward)\n";
  EXPECT_GT(out.genus_before, 0);
  EXPECT_GE(out.coverage, 0.99);
  expect_same_figures(out, in, "full mask");
  expect_reversal_reported(out, in, "full mask");
}

// The mask at half resolution, inward, in each format other tools write (OFF, PLY, legacy VTK,
// VTP): every run has the outward surface's figures and reports the reversal.
TEST(ForeignSurface, EveryFormatInwardRunsLikeOutward) {
  if (!fs::exists(kMask)) GTEST_SKIP() << kMask << " missing";
  testing::TempDir tmp;
  const TriangleList outward = testing::foreign_marching_cubes(kMask, 2);
  const TriangleList inward = testing::reversed_faces(outward);
  // The outward reference of each reader: OpenMesh reads OFF and PLY (text, rounded coordinates),
  // VTK reads legacy VTK and VTP (the same binary floats).
  std::map<std::string, Figures> reference;
  for (const std::string ext : {".off", ".ply", ".vtp"}) {
    testing::write_foreign(outward, tmp / ("outward" + ext));
    reference[ext] = run_from_denoise(tmp / ("outward" + ext), tmp / ("run_out" + ext.substr(1)), false);
    EXPECT_GT(reference[ext].genus_before, 0) << ext;
    EXPECT_GE(reference[ext].coverage, 0.99) << ext;
  }
  reference[".vtk"] = reference[".vtp"];
  for (const std::string ext : {".off", ".ply", ".vtk", ".vtp"}) {
    const Figures& out = reference[ext];
    testing::write_foreign(inward, tmp / ("inward" + ext));
    const Figures in = run_from_denoise(tmp / ("inward" + ext), tmp / ("run" + ext.substr(1)), false);
    std::cout << "half mask " << ext << ": " << outward.triangles.size() << " faces, genus " << in.genus_before
              << ", loops " << out.loops << " / " << in.loops << ", bands " << out.bands << " / " << in.bands
              << ", coverage " << out.coverage << " / " << in.coverage << ", candidates " << out.candidates << " / "
              << in.candidates << " (outward / inward)\n";
    expect_same_figures(out, in, ext);
    expect_reversal_reported(out, in, ext);
  }
}

// The half-resolution surface with a ball of faces flipped (a patch, ~1 % of the faces):
// denoise turns the patch back, says how many faces, and cuts the outward surface's loops.
TEST(ForeignSurface, FlippedPatchIsTurnedBack) {
  if (!fs::exists(kMask)) GTEST_SKIP() << kMask << " missing";
  testing::TempDir tmp;
  const TriangleList outward = testing::foreign_marching_cubes(kMask, 2);
  TriangleList patched = outward;
  const auto& c = outward.points[std::size_t(outward.triangles[outward.triangles.size() / 2][0])];
  std::size_t flipped = 0;
  for (auto& tr : patched.triangles) {
    const auto& p = outward.points[std::size_t(tr[0])];
    if (std::hypot(p[0] - c[0], p[1] - c[1], p[2] - c[2]) < 15.0) std::swap(tr[1], tr[2]), ++flipped;
  }
  ASSERT_GT(flipped, 100u);
  ASSERT_LT(flipped, outward.triangles.size() / 10);
  testing::write_foreign(outward, tmp / "outward.ply");
  testing::write_foreign(patched, tmp / "patched.ply");
  nlohmann::json rep[2];
  int k = 0;
  for (const char* n : {"outward", "patched"}) {
    const auto r = testing::run_colonflat({"denoise", tmp.str(std::string(n) + ".ply"), "-o",
                                           tmp.str(std::string(n) + "_d.vtp"), "--report", tmp.str(std::string(n) + ".json")});
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream s(tmp / (std::string(n) + ".json"));
    rep[k++] = nlohmann::json::parse(s)["result"];
  }
  EXPECT_EQ(rep[1]["orientation"]["flipped_faces"], flipped);
  EXPECT_EQ(rep[1]["orientation"]["reversed_components"], 0);
  EXPECT_NE(rep[1]["orientation"]["notes"][0].get<std::string>().find(std::to_string(flipped) + " faces were oriented against their neighbours; turned"), std::string::npos);
  EXPECT_EQ(rep[1]["totals"]["loops"], rep[0]["totals"]["loops"]);
  EXPECT_EQ(rep[1]["genus_before"], rep[0]["genus_before"]);
}

// A non-orientable surface (a Klein-bottle-like closed surface is not embeddable; a Moebius
// strip is): one error line naming the file and the reason, nothing written.
TEST(ForeignSurface, NonOrientableIsRefusedWithTheReason) {
  TriangleList m;
  const int n = 16;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n, w = 0.3, cw = std::cos(a / 2) * w;
    m.points.push_back({(1 + cw) * std::cos(a), (1 + cw) * std::sin(a), std::sin(a / 2) * w});
    m.points.push_back({(1 - cw) * std::cos(a), (1 - cw) * std::sin(a), -std::sin(a / 2) * w});
  }
  for (int i = 0; i < n; ++i) {
    int a0 = 2 * i, a1 = 2 * i + 1, b0 = 2 * (i + 1), b1 = 2 * (i + 1) + 1;
    if (i == n - 1) b0 = 1, b1 = 0;  // the half twist
    m.triangles.push_back({a0, b0, b1});
    m.triangles.push_back({a0, b1, a1});
  }
  testing::TempDir tmp;
  testing::write_foreign(m, tmp / "moebius.off");
  for (const char* stage : {"denoise", "flatten"}) {
    const auto r = testing::run_colonflat({stage, tmp.str("moebius.off"), "-o", tmp.str("out.vtp")});
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_EQ(r.err.rfind(std::string("colonflat ") + stage + ": error: " + tmp.str("moebius.off") + ": ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find("component 0 (32 faces"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("is not orientable"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(tmp / "out.vtp"));
  }
}

}  // namespace
}  // namespace cf
