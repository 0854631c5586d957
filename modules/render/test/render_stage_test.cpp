// The render stage on its snapshot inputs held as the mesh or, as `colonflat run` holds them from
// denoise on, as their stand-ins (triangle lists: Port::reads_stand_in).
#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include <sstream>

#include "colonflat/core/orientation.h"
#include "colonflat/core/topology.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/synthetic_colon.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/render/render_stage.h"
#include "colonflat/testdata/synthetic.h"

namespace cf {
namespace {

// The bytes of an image's pixels.
std::string pixels(const ImagePtr& img) {
  vtkUnsignedCharArray* a = vtkUnsignedCharArray::SafeDownCast(img->GetPointData()->GetScalars());
  return a ? std::string(reinterpret_cast<const char*>(a->GetPointer(0)), a->GetNumberOfValues()) : std::string();
}

struct Rendered {
  ArtifactBag bag;
  nlohmann::json report;
  std::string log;
};

// Render with snapshots (128 px) on `flat`, the surface before denoising `inward` and after `colon`,
// each put in the bag as the mesh or as its triangle list.
Rendered render(const FlatMap& flat, const TriangleList& inward, const TriangleList& colon, bool as_lists) {
  Rendered r;
  r.bag.put("flat", flat);
  if (as_lists) {
    r.bag.put("surface", inward);
    r.bag.put("denoised", colon);
  } else {
    r.bag.put("surface", build_mesh(inward));
    r.bag.put("denoised", build_mesh(colon));
  }
  auto stage = make_render_stage();
  stage->set_params_json({{"snapshot-size", 128}}, "test");
  std::ostringstream log;
  RunContext ctx;
  ctx.log = &log;
  stage->run(r.bag, ctx);
  r.report = ctx.report;
  r.log = log.str();
  return r;
}

// Both snapshot surfaces given as triangle lists: the same orientation report and progress line
// (the inward surface reversed in the bag's list itself), and, where a display can be had, the
// same snapshots pixel for pixel as from the meshes; the snapshots' ports declare reads_stand_in.
TEST(RenderStage, SnapshotsOfStandInsEqualThoseOfTheMeshes) {
  const TriangleList colon = synthetic::colon(synthetic::colon_options(200, 15, 1.0, {{100, 3.0, 8}})).mesh;
  TriangleList inward = synthetic::sphere(20, 40, 20);
  for (auto& f : inward.triangles) std::swap(f[1], f[2]);
  const FlatMap flat = flatten_colon(colon);
  const Rendered meshes = render(flat, inward, colon, false), lists = render(flat, inward, colon, true);
  EXPECT_EQ(lists.report["orientation"], meshes.report["orientation"]);
  EXPECT_EQ(lists.report["orientation"]["surface"]["reversed_components"], 1) << lists.report.dump();
  EXPECT_NE(lists.log.find("render: surface: component 0"), std::string::npos) << lists.log;
  const TriangleList& reversed = lists.bag.get<TriangleList>("surface");
  EXPECT_EQ(reversed.triangles, to_triangle_list(meshes.bag.get<Mesh>("surface")).triangles);
  EXPECT_EQ(lists.bag.get<TriangleList>("denoised").triangles, colon.triangles);
  EXPECT_EQ(pixels(lists.bag.get<ImagePtr>("colon_image")), pixels(meshes.bag.get<ImagePtr>("colon_image")));
  ASSERT_EQ(lists.report.contains("snapshot_error"), meshes.report.contains("snapshot_error"));
  if (!meshes.report.contains("snapshot_error")) {
    for (const char* s : {"snapshot_before", "snapshot_after"}) {
      const std::string a = pixels(meshes.bag.get<ImagePtr>(s));
      EXPECT_GT(a.size(), 128u * 128u) << s;
      EXPECT_EQ(pixels(lists.bag.get<ImagePtr>(s)), a) << s;
    }
  }
  for (const Port& in : make_render_stage()->spec().inputs)
    EXPECT_EQ(in.reads_stand_in, in.name == "surface" || in.name == "denoised") << in.name;
}

}  // namespace
}  // namespace cf
