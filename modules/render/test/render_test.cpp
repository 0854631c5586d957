// The colon image (size, wall pixels, overlays), candidate JSON, known polyps, off-screen 3D
// snapshots (own Xvfb when there is no display) and the `colonflat render` command.
#include <gtest/gtest.h>

#include <vtkCellArray.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkCellData.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataNormals.h>
#include <vtkPointData.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "colonflat/core/mesh_io.h"
#include "colonflat/core/orientation.h"
#include "colonflat/core/threads.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/flatten/flat_artifact.h"
#include "colonflat/flatten/flatten.h"
#include "colonflat/flatten/synthetic_colon.h"
#include "colonflat/render/artifacts.h"
#include "colonflat/render/colon_image.h"
#include "colonflat/render/render_stage.h"
#include "colonflat/render/snapshot.h"
#include "colonflat/testing/stage_command.h"
#include "colonflat/testing/temp_dir.h"

namespace cf {
namespace {

synthetic::Colon test_colon() {
  return synthetic::colon(synthetic::colon_options(300, 18, 0.8, {{45, 0.3, 8}, {150, 3.0, 10}, {220, 5.0, 7}}));
}

const unsigned char* at(vtkImageData* img, int col, int row_from_top) {
  int e[6];
  img->GetExtent(e);
  const int h = e[3] - e[2] + 1;
  return static_cast<unsigned char*>(img->GetScalarPointer(col, h - 1 - row_from_top, 0));
}

// The image is length/pixel wide plus margins, the wall is drawn (tissue colour) where the map is,
// every polyp is a candidate and is marked at a wall pixel; the PNG reads back the same size.
TEST(RenderImage, ColonImageShowsWallAndCandidates) {
  testing::TempDir tmp;
  auto c = test_colon();
  FlatMap f = flatten_colon(c.mesh);
  RenderOptions o;
  o.pixel_size = 0.5;
  RenderResult r = render_flat(f, o);
  const auto& s = f.segments[0];
  EXPECT_EQ(r.colon.width, int(std::ceil(s.length / 0.5)) + 60);
  EXPECT_EQ(r.colon.height, int(std::ceil(s.period / 0.5)) + 70 + 90);
  EXPECT_EQ(r.colon.missing_pixels, 0u);
  ASSERT_EQ(r.candidates.size(), 3u);
  // wall pixels: reddish tissue, not the dark background
  const unsigned char* p = at(r.colon.image, r.colon.width / 2, 70 + int(s.period / 0.5 / 2));
  EXPECT_GT(p[0], 40);
  EXPECT_GT(p[0], p[2]);
  for (const auto& m : r.markers) {
    EXPECT_GT(m.px, 30);
    EXPECT_LT(m.px, r.colon.width - 30);
    EXPECT_GT(m.py, 70);
    EXPECT_LT(m.py, r.colon.height - 70);
    // the outline ring is drawn in yellow at the marker's radius somewhere around the centre
    bool yellow = false;
    for (int dy = -30; dy <= 30 && !yellow; ++dy)
      for (int dx = -30; dx <= 30 && !yellow; ++dx) {
        const unsigned char* q = at(r.colon.image, int(m.px) + dx, int(m.py) + dy);
        yellow = q[0] == 255 && q[1] == 230 && q[2] == 0;
      }
    EXPECT_TRUE(yellow) << m.label;
  }
  const auto& cj = r.candidates_json["candidates"];
  ASSERT_EQ(cj.size(), 3u);
  EXPECT_EQ(cj[0]["id"], 1);
  EXPECT_TRUE(cj[0].contains("center_lps_mm"));
  EXPECT_TRUE(cj[0].contains("flat_mm"));
  EXPECT_GT(cj[0]["size_mm"].get<double>(), 4.0);
  write_png(r.colon.image, tmp / "colon.png");
  ImagePtr back = read_png(tmp / "colon.png");
  int dims[3];
  back->GetDimensions(dims);
  EXPECT_EQ(dims[0], r.colon.width);
  EXPECT_EQ(dims[1], r.colon.height);
}

// Wall left out of the map is hatched, not silently dropped: removing triangles from the flat map
// gives missing (hatched) pixels in proportion to the removed area.
TEST(RenderImage, MissingWallIsHatched) {
  auto c = test_colon();
  FlatMap f = flatten_colon(c.mesh);
  ColonImageOptions o;
  std::vector<ImageMarker> none;
  const ColonImage full = render_colon_image(f, {}, none, o);
  EXPECT_EQ(full.missing_pixels, 0u);
  double removed = 0;
  std::vector<std::array<int, 3>> kept;
  for (const auto& t : f.triangles) {
    const auto &a = f.uv[t[0]], &b = f.uv[t[1]], &d = f.uv[t[2]];
    const bool inside = a[0] > 100 && a[0] < 120 && b[0] > 100 && b[0] < 120 && d[0] > 100 && d[0] < 120;
    if (inside) removed += 0.5 * std::abs((b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]));
    else kept.push_back(t);
  }
  f.triangles = kept;
  const ColonImage holed = render_colon_image(f, {}, none, o);
  const double px_area = holed.pixel_size * holed.pixel_size;
  EXPECT_NEAR(double(holed.missing_pixels) * px_area, removed, 0.15 * removed);
}

// A disk band (flatten's disk_map.h: the disk's own outline inside its bounding box) leaves the box
// outside the disk unpainted, not hatched as missing wall: the same holed map as above, its band marked
// "disk", has no missing pixels.
TEST(RenderImage, DiskBandsEmptyBoxIsNotMissingWall) {
  auto c = test_colon();
  FlatMap f = flatten_colon(c.mesh);
  std::vector<std::array<int, 3>> kept;
  for (const auto& t : f.triangles)
    if (!(f.uv[t[0]][0] > 100 && f.uv[t[0]][0] < 120)) kept.push_back(t);
  f.triangles = kept;
  std::vector<ImageMarker> none;
  ASSERT_GT(render_colon_image(f, {}, none, ColonImageOptions{}).missing_pixels, 0u);
  for (FlatSegment& s : f.segments) s.map = "disk";
  EXPECT_EQ(render_colon_image(f, {}, none, ColonImageOptions{}).missing_pixels, 0u);
}

// A band's caption says what it shows: a side branch holding tissue (flatten's "holds", a crushed
// strand stump: FlattenBranches.CrushedTissueStrandIsABandOfItsOwn) is a "tissue strand (cut
// bridge)", never a pouch; one holding lumen stays "side branch (pouch)"; a patch of wall its parent's
// map hid ("wall") is a "wall patch", never a pouch; the colon band is none of these.
TEST(RenderImage, BandCaptionSaysPouchOrTissueStrand) {
  FlatSegment colon, branch;
  colon.id = 0, colon.length = 200, colon.period = 75;
  branch.id = 1, branch.kind = "branch", branch.parent = 0, branch.attach_mm = 104, branch.neck_mm = 7;
  branch.length = 36, branch.period = 6, branch.x0_end = "neck", branch.x1_end = "tip";
  branch.holds = "lumen";
  const std::string pouch = band_caption(branch);
  EXPECT_EQ(pouch.rfind("segment 2: side branch (pouch) of segment 1 at 10 cm, neck 7 mm around; 36 mm long", 0), 0u)
      << pouch;
  branch.holds = "tissue";
  const std::string strand = band_caption(branch);
  EXPECT_EQ(strand.rfind("segment 2: tissue strand (cut bridge) off segment 1 at 10 cm, neck 7 mm around; ", 0), 0u)
      << strand;
  EXPECT_EQ(strand.find("pouch"), std::string::npos) << strand;
  branch.holds = "wall";  // a patch: wall its parent's map hid (flatten's hidden patches)
  const std::string patch = band_caption(branch);
  EXPECT_EQ(patch.rfind("segment 2: wall patch (hidden in the map of) segment 1 at 10 cm, rim 7 mm around; ", 0), 0u)
      << patch;
  EXPECT_EQ(patch.find("pouch"), std::string::npos) << patch;
  EXPECT_EQ(neck_label(branch), "patch: segment 2");  // its mark on the parent band
  branch.holds = "lumen";
  EXPECT_EQ(neck_label(branch), "branch: segment 2");
  const std::string band = band_caption(colon);
  EXPECT_EQ(band.rfind("segment 1: 200 mm long x 75 mm around; end A (left) to end B (right); ", 0), 0u) << band;
  EXPECT_EQ(band.find("pouch"), std::string::npos);
  EXPECT_EQ(band.find("tissue"), std::string::npos);
}

// A disk band's caption (flatten's disk map: a wall patch mapped as itself) names its box, not a
// length "around" a tube it is not, and no ends: its rim is the outline.
TEST(RenderImage, DiskBandCaptionNamesItsBoxNotATube) {
  FlatSegment patch;
  patch.id = 4, patch.kind = "branch", patch.parent = 0, patch.attach_mm = 1520, patch.neck_mm = 41;
  patch.holds = "wall", patch.map = "disk", patch.length = 70, patch.period = 49, patch.x0_end = "rim", patch.x1_end = "rim";
  const std::string caption = band_caption(patch);
  EXPECT_EQ(caption, "segment 5: wall patch (hidden in the map of) segment 1 at 152 cm, rim 41 mm around; "
                     "mapped as a disk in a 70 x 49 mm box, its rim the outline; ");
  patch.map = "conformal";  // the same patch mapped as a tube keeps the tube's wording
  EXPECT_NE(band_caption(patch).find("70 mm long x 49 mm around; rim (left) to rim (right); "), std::string::npos);
}

// The colon image is the same, pixel for pixel and in its counts, for 1 and 2 threads (a hole
// in the map makes hatched pixels count too).
TEST(RenderImage, SameImageForAnyThreadCount) {
  auto c = test_colon();
  FlatMap f = flatten_colon(c.mesh);
  std::vector<std::array<int, 3>> kept;
  for (const auto& t : f.triangles)
    if (f.uv[t[0]][0] < 100 || f.uv[t[0]][0] > 110) kept.push_back(t);
  f.triangles = kept;
  std::vector<ImageMarker> none;
  ColonImageOptions o;
  o.color = "curvature";
  std::vector<double> si(f.uv.size());
  for (std::size_t v = 0; v < si.size(); ++v) si[v] = std::sin(0.1 * f.uv[v][0]);
  set_thread_count(1);
  const ColonImage one = render_colon_image(f, si, none, o);
  set_thread_count(2);
  const ColonImage two = render_colon_image(f, si, none, o);
  set_thread_count(0);
  ASSERT_GT(one.missing_pixels, 0u);
  EXPECT_EQ(one.missing_pixels, two.missing_pixels);
  EXPECT_EQ(one.compressed_pixels, two.compressed_pixels);
  ASSERT_EQ(one.width, two.width);
  ASSERT_EQ(one.height, two.height);
  const auto* a = static_cast<const unsigned char*>(one.image->GetScalarPointer());
  const auto* b = static_cast<const unsigned char*>(two.image->GetScalarPointer());
  EXPECT_TRUE(std::equal(a, a + std::size_t(one.width) * one.height * 3, b));
}

// Wall the image cannot show (a coverage cluster of flatten) is ringed in red at the mapped point
// nearest to the cluster's LPS centroid; without the cluster the same pixels are not red.
TEST(RenderImage, NotShownWallIsRingedAtItsPlace) {
  auto c = test_colon();
  FlatMap f = flatten_colon(c.mesh);
  f.segments[0].coverage.not_shown.clear();
  std::vector<ImageMarker> none;
  ColonImageOptions o;
  std::size_t v = 0;  // a vertex in the middle of the band
  for (std::size_t i = 0; i < f.uv.size(); ++i)
    if (std::abs(f.uv[i][0] - 110) + std::abs(f.uv[i][1] - f.segments[0].y0 - 0.5 * f.segments[0].period) <
        std::abs(f.uv[v][0] - 110) + std::abs(f.uv[v][1] - f.segments[0].y0 - 0.5 * f.segments[0].period))
      v = i;
  const ColonImage plain = render_colon_image(f, {}, none, o);
  Coverage::Cluster cl;
  cl.centroid_lps_mm = f.position[v];
  cl.area_mm2 = 500;
  f.segments[0].coverage.not_shown.push_back(cl);
  const ColonImage ringed = render_colon_image(f, {}, none, o);
  const ColonImageGeometry g = colon_image_geometry(f, o.pixel_size, o.max_width);
  const FlatSegment& s = f.segments[0];
  const int cx = int(g.bands[0].col0 + (f.uv[v][0] - s.x0) / g.pixel_size);
  const int cy = int(g.bands[0].row_bottom + (f.uv[v][1] - s.y0) / g.pixel_size);
  auto red = [](const ColonImage& im, int x, int y) {
    const auto* p = static_cast<const unsigned char*>(im.image->GetScalarPointer(x, y, 0));
    return p[0] == 255 && p[1] == 60 && p[2] == 60;
  };
  int ring = 0, before = 0;
  for (int d : {-9, 9})
    for (int k = -5; k <= 5; ++k) ring += red(ringed, cx + d, cy + k) + red(ringed, cx + k, cy + d),
                                  before += red(plain, cx + d, cy + k) + red(plain, cx + k, cy + d);
  EXPECT_GE(ring, 40);  // 44 ring pixels probed, 4 sides x 11
  EXPECT_EQ(before, 0);
}

// Known polyps are placed on the nearest wall point and scored against the candidates.
TEST(RenderImage, KnownPolypsAreOverlaidAndScored) {
  testing::TempDir tmp;
  auto c = test_colon();
  nlohmann::json j = nlohmann::json::array();
  for (const auto& p : c.polyps) j.push_back({{"id", p.id}, {"center_lps_mm", p.center}, {"diameter_mm", p.diameter}});
  std::ofstream(tmp / "known.json") << j.dump();
  RenderOptions o;
  o.known_polyps = tmp.str("known.json");
  o.color = "curvature";
  RenderResult r = render_flat(flatten_colon(c.mesh), o);
  const auto& kj = r.candidates_json["known_polyps"];
  ASSERT_EQ(kj.size(), 3u);
  for (const auto& k : kj) EXPECT_LT(k["distance_to_surface_mm"].get<double>(), 1.0);
  EXPECT_EQ(r.candidates_json["score_vs_known"]["sensitivity"], 1.0);
  EXPECT_EQ(r.candidates_json["score_vs_known"]["false_positives"], 0);
}

// One marker keeps its label's old place (none moved, none crowded); 60 markers at one place with
// long labels cannot all find a free spot: every one is still drawn, the crowded ones are counted
// and listed with their text, and the rest moved.
TEST(RenderImage, CrowdedMarkerLabelsAreCountedAndListed) {
  const FlatMap f = flatten_colon(test_colon().mesh);
  ColonImageOptions o;
  std::vector<ImageMarker> one(1);
  one[0].x = f.segments[0].x0 + 0.5 * f.segments[0].length, one[0].y = f.segments[0].y0, one[0].label = "P1 8 mm";
  const ColonImage lone = render_colon_image(f, {}, one, o);
  EXPECT_EQ(lone.labels_moved, 0);
  EXPECT_EQ(lone.labels_crowded, 0);
  std::vector<ImageMarker> many(60, one[0]);
  for (std::size_t i = 0; i < many.size(); ++i) many[i].label = "P" + std::to_string(i + 1) + " a long candidate label here";
  const ColonImage pile = render_colon_image(f, {}, many, o);
  EXPECT_GT(pile.labels_crowded, 0);
  ASSERT_EQ(pile.crowded_labels.size(), std::size_t(pile.labels_crowded));
  EXPECT_EQ(pile.crowded_labels[0].rfind("P", 0), 0u) << pile.crowded_labels[0];
  EXPECT_GE(pile.labels_moved, 59);
}

// Off-screen VTK rendering works without a display (a private Xvfb is started): the sphere is
// drawn over the background and a loop polyline is visible in red.
TEST(RenderSnapshot, OffScreenWithoutDisplay) {
  auto sphere = synthetic::sphere(20, 48, 24);
  vtkNew<vtkPoints> pts;
  for (int k = 0; k < 64; ++k) pts->InsertNextPoint(20.5 * std::cos(2 * M_PI * k / 64), -0.0, 20.5 * std::sin(2 * M_PI * k / 64));
  vtkNew<vtkCellArray> lines;
  std::vector<vtkIdType> ids(65);
  for (int k = 0; k < 65; ++k) ids[k] = k % 64;
  lines->InsertNextCell(65, ids.data());
  vtkNew<vtkPolyData> loops;
  loops->SetPoints(pts);
  loops->SetLines(lines);
  vtkNew<vtkIntArray> type;
  type->SetName("type");
  type->InsertNextValue(0);
  loops->GetCellData()->AddArray(type);
  SnapshotOptions so;
  so.width = so.height = 300;
  ImagePtr img;
  ASSERT_NO_THROW(img = render_snapshot(sphere, loops, so));
  int dims[3];
  img->GetDimensions(dims);
  EXPECT_EQ(dims[0], 300);
  EXPECT_EQ(dims[1], 300);
  const unsigned char* corner = at(img, 2, 2);
  const unsigned char* centre = at(img, 150, 150);
  EXPECT_GT(std::abs(int(centre[0]) - int(corner[0])), 40);
  int red = 0;
  for (int y = 0; y < 300; ++y)
    for (int x = 0; x < 300; ++x) {
      const unsigned char* q = at(img, x, y);
      if (q[0] > 150 && q[1] < 90 && q[2] < 90) ++red;
    }
  EXPECT_GT(red, 50);
}

// The snapshots' own point normals are vtkPolyDataNormals' (no splitting, no reorienting) on a
// sphere with a degenerate triangle: the same directions within float rounding, and surface_polydata
// keeps every point and triangle in order.
TEST(RenderSnapshot, PointNormalsAreVtkPolyDataNormals) {
  TriangleList sphere = synthetic::sphere(20, 40, 20);
  sphere.triangles.push_back({0, 0, 1});  // degenerate: adds nothing to its points' normals
  vtkSmartPointer<vtkPolyData> pd = surface_polydata(sphere);
  ASSERT_EQ(pd->GetNumberOfPoints(), vtkIdType(sphere.points.size()));
  ASSERT_EQ(pd->GetNumberOfPolys(), vtkIdType(sphere.triangles.size()));
  vtkNew<vtkIdList> ids;
  pd->GetCellPoints(7, ids);
  EXPECT_EQ(ids->GetId(2), sphere.triangles[7][2]);
  vtkNew<vtkPolyDataNormals> ref;
  ref->SetInputData(pd);
  ref->SplittingOff();
  ref->ConsistencyOff();
  ref->Update();
  vtkDataArray* want = ref->GetOutput()->GetPointData()->GetNormals();
  vtkSmartPointer<vtkFloatArray> got = smooth_point_normals(sphere);
  ASSERT_EQ(got->GetNumberOfTuples(), want->GetNumberOfTuples());
  for (vtkIdType v = 0; v < got->GetNumberOfTuples(); ++v)
    for (int k = 0; k < 3; ++k) ASSERT_NEAR(got->GetComponent(v, k), want->GetComponent(v, k), 1e-6) << v;
}

// Bitwise equality of two lit polydata: points, triangle ids in order, point normals.
void expect_same_lit_polydata(vtkPolyData* got, vtkPolyData* want) {
  ASSERT_EQ(got->GetNumberOfPoints(), want->GetNumberOfPoints());
  ASSERT_EQ(got->GetNumberOfPolys(), want->GetNumberOfPolys());
  for (vtkIdType i = 0; i < got->GetNumberOfPoints(); ++i)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(got->GetPoint(i)[k], want->GetPoint(i)[k]) << i;
  vtkNew<vtkIdList> a, b;
  for (vtkIdType c = 0; c < got->GetNumberOfPolys(); ++c) {
    got->GetCellPoints(c, a);
    want->GetCellPoints(c, b);
    ASSERT_EQ(a->GetNumberOfIds(), 3);
    ASSERT_EQ(b->GetNumberOfIds(), 3);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(a->GetId(k), b->GetId(k)) << "triangle " << c;
  }
  vtkDataArray* na = got->GetPointData()->GetNormals();
  vtkDataArray* nb = want->GetPointData()->GetNormals();
  ASSERT_TRUE(na && nb);
  for (vtkIdType v = 0; v < na->GetNumberOfTuples(); ++v)
    for (int k = 0; k < 3; ++k) ASSERT_EQ(na->GetComponent(v, k), nb->GetComponent(v, k)) << v;
}

// The snapshot's polydata built straight from a mesh is bit for bit the one of its
// to_triangle_list (corners in the same order after edge flips moved the faces' halfedges), for
// 1 and 3 threads, and a mesh with a deleted vertex (not garbage-collected) too.
TEST(RenderSnapshot, MeshPolydataIsTriangleListPolydata) {
  Mesh m = synthetic::to_mesh(synthetic::sphere(20, 40, 20));
  int flipped = 0;
  for (auto e : m.edges())
    if (e.idx() % 7 == 0 && m.is_flip_ok(e)) m.flip(e), ++flipped;
  ASSERT_GT(flipped, 50);
  for (int threads : {1, 3}) {
    set_thread_count(threads);
    expect_same_lit_polydata(lit_surface_polydata(m), lit_surface_polydata(to_triangle_list(m)));
  }
  m.delete_vertex(Mesh::VertexHandle(5));  // its faces are deleted with it; no garbage collection
  expect_same_lit_polydata(lit_surface_polydata(m), lit_surface_polydata(to_triangle_list(m)));
  set_thread_count(0);
}

testing::CommandResult render_cli(const std::vector<std::string>& args) {
  return testing::run_stage_command(make_render_stage, args);
}

// Components orient_outward would reverse in a copy of `t`: 0 when every closed one faces outward.
std::size_t inward_components(TriangleList t) {
  const TopologyReport topo = analyze_topology(t);
  return orient_outward(t, topo).reversed_components();
}

// The stage orients its snapshot surfaces (on the snapshot thread, beside the colon image): a closed
// surface whose normals point into it is reversed in the bag and reported under "orientation" with
// its progress line; the surface after denoising, already outward, is left as it is.
TEST(RenderStage, SnapshotThreadOrientsTheSurfacesAndReportsIt) {
  auto c = test_colon();
  TriangleList inward = synthetic::sphere(20, 40, 20);
  for (auto& f : inward.triangles) std::swap(f[1], f[2]);
  ASSERT_EQ(inward_components(inward), 1u);
  ArtifactBag bag;
  bag.put("flat", flatten_colon(c.mesh));
  bag.put("surface", build_mesh(inward));
  bag.put("denoised", build_mesh(c.mesh));
  auto stage = make_render_stage();
  stage->set_params_json({{"snapshot-size", 128}}, "test");
  std::ostringstream log;
  RunContext ctx;
  ctx.log = &log;
  stage->run(bag, ctx);
  EXPECT_EQ(ctx.report["orientation"]["surface"]["reversed_components"], 1) << ctx.report.dump();
  EXPECT_EQ(ctx.report["orientation"]["denoised"]["reversed_components"], 0);
  EXPECT_GE(ctx.report["snapshot_orient_s"].get<double>(), 0.0);
  EXPECT_NE(log.str().find("render: surface: component 0"), std::string::npos) << log.str();
  EXPECT_EQ(inward_components(to_triangle_list(bag.get<Mesh>("surface"))), 0u);
  EXPECT_EQ(to_triangle_list(bag.get<Mesh>("denoised")).triangles, c.mesh.triangles);
  if (!ctx.report.contains("snapshot_error")) EXPECT_TRUE(bag.has("snapshot_before"));
}

// `colonflat render` writes the colon PNG, the candidate JSON and both snapshots.
TEST(RenderCli, WritesImageJsonAndSnapshots) {
  testing::TempDir tmp;
  auto c = test_colon();
  write_mesh(synthetic::to_mesh(c.mesh), tmp / "surface.vtp");
  write_flat(flatten_colon(c.mesh), tmp / "flat.vtp");
  auto r = render_cli({tmp.str("flat.vtp"), "-o", tmp.str("colon.png"), "--candidates", tmp.str("polyps.json"),
                       "--surface", tmp.str("surface.vtp"), "--snapshot-before", tmp.str("before.png"),
                       "--snapshot-after", tmp.str("after.png"), "--snapshot-size", "256", "-q"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(read_json_file(tmp / "polyps.json")["candidates"].size(), 3u);
  int d[3];
  read_png(tmp / "before.png")->GetDimensions(d);
  EXPECT_EQ(d[0], 256);
  read_png(tmp / "colon.png")->GetDimensions(d);
  EXPECT_GT(d[0], 600);
  auto bad = render_cli({tmp.str("surface.vtp"), "-o", tmp.str("x.png")});
  EXPECT_EQ(bad.code, 3);
  EXPECT_NE(bad.err.find("not a flat colon map"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace cf
