#include "colonflat/reconstruct/reconstruct.h"

#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/McDecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <vtkCellArray.h>
#include <vtkCellArrayIterator.h>
#include <vtkDiscreteFlyingEdges3D.h>
#include <vtkDoubleArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkMarchingCubes.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/soup.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/vtk_messages.h"

namespace cf {

const ParamTable<ReconstructOptions>& reconstruct_param_table() {
  static const ParamTable<ReconstructOptions> t = [] {
    ParamTable<ReconstructOptions> t;
    t.choice("method", &ReconstructOptions::method, {"flying-edges", "discrete-flying-edges", "marching-cubes"},
             "VTK isosurface filter run on the binary mask (all give the same closed manifold surface)");
    t.real("min-component-volume", &ReconstructOptions::min_component_volume, "mm^3",
           "drop surface components enclosing less than this (noise, tiny air pockets or cavities)", 0.0);
    t.integer("smoothing-iterations", &ReconstructOptions::smoothing_iterations, "",
              "windowed-sinc smoothing iterations (moves points only; 0 = off)", 0, 1000);
    t.real("pass-band", &ReconstructOptions::pass_band, "", "windowed-sinc pass band (smaller = smoother)", 0.001,
           2.0);
    t.integer("target-faces", &ReconstructOptions::target_faces, "",
              "topology-preserving quadric decimation to about this many triangles (0 = off)", 0);
    return t;
  }();
  return t;
}

void validate(const ReconstructOptions& o) { reconstruct_param_table().validate(o); }

nlohmann::json ReconstructStats::to_json() const {
  auto comp = [](const ReconstructComponent& c) {
    return nlohmann::json{{"faces", c.faces}, {"volume_mm3", c.volume_mm3}, {"area_mm2", c.area_mm2}, {"genus", c.genus}};
  };
  nlohmann::json kept_j = nlohmann::json::array(), dropped_j = nlohmann::json::array();
  for (const auto& c : kept) kept_j.push_back(comp(c));
  double dropped_volume = 0;
  for (std::size_t i = 0; i < dropped.size(); ++i) {
    dropped_volume += std::abs(dropped[i].volume_mm3);
    if (i < 20) dropped_j.push_back(comp(dropped[i]));  // the 20 largest; the count says how many
  }
  return {{"method", method},
          {"lumen_voxels", lumen_voxels},
          {"image_size", image_size},
          {"crop_size", crop_size},
          {"direction_flips_orientation", direction_flips_orientation},
          {"extracted_vertices", extracted_vertices},
          {"extracted_faces", extracted_faces},
          {"mask_euler_characteristic_6_18", mask_euler_6_18},
          {"extracted_euler_characteristic", surface_euler},
          {"components_found", components_found},
          {"components", kept.size()},
          {"components_dropped", dropped.size()},
          {"dropped_volume_mm3", dropped_volume},
          {"kept_components", kept_j},
          {"largest_dropped_components", dropped_j},
          {"smoothed", smoothed},
          {"decimated", decimated},
          {"vertices", vertices},
          {"faces", faces},
          {"genus", genus},
          {"closed", true},
          {"manifold", true},
          {"units", "mm"},
          {"coordinate_system", "LPS"},
          {"time_extract_s", time_extract_s},
          {"time_check_s", time_check_s},
          {"time_smooth_s", time_smooth_s},
          {"time_decimate_s", time_decimate_s},
          {"time_total_s", time_total_s}};
}

namespace {

// Contribution of one 2x2x2 block (bit b = corner (b&1, b>>1&1, b>>2&1)) anchored at its lowest
// corner to the (6,18) Euler characteristic: the anchor voxel, its three face-adjacent pairs,
// three 2x2 squares and the block, plus one for a block whose only two background voxels are
// opposite corners (marching cubes closes that block: the background is 18-, not 26-connected).
struct EulerTable {
  int v[256];
  EulerTable() {
    for (int c = 0; c < 256; ++c) {
      auto b = [c](int i) { return (c >> i) & 1; };
      int x = b(0);
      x -= (b(0) & b(1)) + (b(0) & b(2)) + (b(0) & b(4));
      x += (b(0) & b(1) & b(2) & b(3)) + (b(0) & b(1) & b(4) & b(5)) + (b(0) & b(2) & b(4) & b(6));
      x -= (c == 255);
      int bg = 0;
      for (int i = 0; i < 8; ++i) bg += !b(i);
      if (bg == 2)
        for (int i = 0; i < 4; ++i)
          if (!b(i) && !b(7 - i)) x += 1;
      v[c] = x;
    }
  }
};

// Euler characteristic of a binary volume (values 0/1, x fastest) whose last slice in each
// direction is background.
long long euler_6_18(const unsigned char* d, std::size_t nx, std::size_t ny, std::size_t nz) {
  static const EulerTable table;
  long long chi = 0;
  const std::size_t sy = nx, sz = nx * ny;
  for (std::size_t k = 0; k + 1 < nz; ++k)
    for (std::size_t j = 0; j + 1 < ny; ++j) {
      const unsigned char* r = d + k * sz + j * sy;
      for (std::size_t i = 0; i + 1 < nx; ++i) {
        const unsigned char* p = r + i;
        const int c = p[0] | p[1] << 1 | p[sy] << 2 | p[sy + 1] << 3 | p[sz] << 4 | p[sz + 1] << 5 | p[sz + sy] << 6 |
                      p[sz + sy + 1] << 7;
        chi += table.v[c];
      }
    }
  return chi;
}

struct Box {
  std::array<std::size_t, 3> lo{0, 0, 0}, hi{0, 0, 0};  // inclusive lumen bounding box (buffer indices)
  std::size_t count = 0;
};

Box lumen_box(const unsigned char* d, const std::array<std::size_t, 3>& n) {
  Box b;
  b.lo = n;
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j) {
      const unsigned char* r = d + (k * n[1] + j) * n[0];
      std::size_t first = n[0], last = 0, cnt = 0;
      for (std::size_t i = 0; i < n[0]; ++i)
        if (r[i]) {
          if (first == n[0]) first = i;
          last = i;
          ++cnt;
        }
      if (!cnt) continue;
      b.count += cnt;
      b.lo = {std::min(b.lo[0], first), std::min(b.lo[1], j), std::min(b.lo[2], k)};
      b.hi = {std::max(b.hi[0], last), std::max(b.hi[1], j), std::max(b.hi[2], k)};
    }
  return b;
}

// The cropped lumen, binarised, with one voxel of background on every side, as VTK image data
// in index space (origin = buffer index of its first voxel, spacing 1).
vtkSmartPointer<vtkImageData> padded_crop(const unsigned char* d, const std::array<std::size_t, 3>& n, const Box& b) {
  const int px = int(b.hi[0] - b.lo[0] + 3), py = int(b.hi[1] - b.lo[1] + 3), pz = int(b.hi[2] - b.lo[2] + 3);
  auto img = vtkSmartPointer<vtkImageData>::New();
  img->SetDimensions(px, py, pz);
  img->SetOrigin(double(b.lo[0]) - 1, double(b.lo[1]) - 1, double(b.lo[2]) - 1);
  img->SetSpacing(1, 1, 1);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* out = static_cast<unsigned char*>(img->GetScalarPointer());
  std::memset(out, 0, std::size_t(px) * py * pz);
  const std::size_t w = b.hi[0] - b.lo[0] + 1;
  for (std::size_t k = b.lo[2]; k <= b.hi[2]; ++k)
    for (std::size_t j = b.lo[1]; j <= b.hi[1]; ++j) {
      const unsigned char* src = d + (k * n[1] + j) * n[0] + b.lo[0];
      unsigned char* dst = out + ((k - b.lo[2] + 1) * py + (j - b.lo[1] + 1)) * std::size_t(px) + 1;
      for (std::size_t i = 0; i < w; ++i) dst[i] = src[i] != 0;
    }
  return img;
}

vtkSmartPointer<vtkPolyData> isosurface(vtkImageData* img, const std::string& method) {
  VtkMessageCapture capture;
  vtkSmartPointer<vtkPolyData> out;
  if (method == "flying-edges") {
    vtkNew<vtkFlyingEdges3D> f;
    f->SetInputData(img);
    f->SetValue(0, 0.5);
    f->ComputeNormalsOff();
    f->ComputeGradientsOff();
    f->ComputeScalarsOff();
    f->InterpolateAttributesOff();
    f->Update();
    out = f->GetOutput();
  } else if (method == "discrete-flying-edges") {
    vtkNew<vtkDiscreteFlyingEdges3D> f;
    f->SetInputData(img);
    f->SetValue(0, 1);
    f->ComputeNormalsOff();
    f->ComputeGradientsOff();
    f->ComputeScalarsOff();
    f->Update();
    out = f->GetOutput();
  } else if (method == "marching-cubes") {
    vtkNew<vtkMarchingCubes> f;
    f->SetInputData(img);
    f->SetValue(0, 0.5);
    f->ComputeNormalsOff();
    f->ComputeGradientsOff();
    f->ComputeScalarsOff();
    f->Update();
    out = f->GetOutput();
  } else {
    throw UsageError("unknown reconstruction method '" + method + "'");
  }
  if (!capture.errors().empty()) throw Error(method + " failed: " + capture.first_problem());
  return out;
}

// Index -> LPS mm: p = origin + direction * diag(spacing) * index.
struct IndexToLps {
  double m[3][3], o[3];
  std::array<double, 3> operator()(const double* x) const {
    std::array<double, 3> p;
    for (int r = 0; r < 3; ++r) p[r] = o[r] + m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2];
    return p;
  }
};

// Points mapped to LPS; triangles reversed when the map reverses orientation.
TriangleList to_lps(vtkPolyData* pd, const IndexToLps& map, bool flip) {
  TriangleList t;
  vtkPoints* pts = pd->GetPoints();
  const vtkIdType np = pts ? pts->GetNumberOfPoints() : 0;
  t.points.resize(std::size_t(np));
  for (vtkIdType i = 0; i < np; ++i) {
    double x[3];
    pts->GetPoint(i, x);
    t.points[std::size_t(i)] = map(x);
  }
  vtkCellArray* polys = pd->GetPolys();
  t.triangles.reserve(std::size_t(polys->GetNumberOfCells()));
  auto it = vtk::TakeSmartPointer(polys->NewIterator());
  for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell()) {
    vtkIdType n;
    const vtkIdType* ids;
    it->GetCurrentCell(n, ids);
    if (n != 3) throw Error("isosurface produced a polygon with " + std::to_string(n) + " vertices");
    if (flip) t.triangles.push_back({int(ids[0]), int(ids[2]), int(ids[1])});
    else t.triangles.push_back({int(ids[0]), int(ids[1]), int(ids[2])});
  }
  return t;
}

using P3 = std::array<double, 3>;
P3 sub(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
P3 cross(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Signed volume and area per component; volumes relative to `ref` (any point; the sum over a
// closed component does not depend on it, but a near point keeps the sums accurate).
void measure(const TriangleList& t, const std::vector<int>& comp, std::size_t ncomp, const P3& ref,
             std::vector<ReconstructComponent>& out) {
  out.assign(ncomp, {});
  for (std::size_t f = 0; f < t.triangles.size(); ++f) {
    const auto& tri = t.triangles[f];
    const P3 a = sub(t.points[tri[0]], ref), b = sub(t.points[tri[1]], ref), c = sub(t.points[tri[2]], ref);
    auto& o = out[std::size_t(comp[f])];
    o.faces += 1;
    o.volume_mm3 += dot(a, cross(b, c)) / 6.0;
    const P3 n = cross(sub(b, a), sub(c, a));
    o.area_mm2 += 0.5 * std::sqrt(dot(n, n));
  }
}

std::string describe_topology_failure(const TopologyReport& r) {
  std::ostringstream s;
  s << r.boundary_edges << " boundary edges, " << r.nonmanifold_edges << " non-manifold edges, "
    << r.nonmanifold_vertices << " non-manifold vertices, " << r.inconsistent_edges << " inconsistently oriented edges";
  return s.str();
}

Mesh to_openmesh(const TriangleList& t) {
  Mesh m;
  m.reserve(t.points.size(), t.points.size() + t.triangles.size(), t.triangles.size());
  for (const auto& p : t.points) m.add_vertex(Vec3(p[0], p[1], p[2]));
  for (const auto& tri : t.triangles) {
    const auto f = m.add_face(Mesh::VertexHandle(tri[0]), Mesh::VertexHandle(tri[1]), Mesh::VertexHandle(tri[2]));
    if (!f.is_valid()) throw Error("reconstruct: internal error: surface triangle rejected by the halfedge mesh");
  }
  return m;
}

}  // namespace

long long mask_euler_characteristic_6_18(const MaskImage* mask) {
  if (!mask) throw PreconditionError("no mask");
  const auto size = mask->GetBufferedRegion().GetSize();
  const std::array<std::size_t, 3> n{size[0], size[1], size[2]};
  const Box b = lumen_box(mask->GetBufferPointer(), n);
  if (!b.count) return 0;
  auto img = padded_crop(mask->GetBufferPointer(), n, b);
  int dims[3];
  img->GetDimensions(dims);
  return euler_6_18(static_cast<const unsigned char*>(img->GetScalarPointer()), dims[0], dims[1], dims[2]);
}

Mesh reconstruct_surface(const MaskImage* mask, const ReconstructOptions& options, ReconstructStats* stats_out) {
  validate(options);
  if (!mask) throw PreconditionError("no mask");
  Stopwatch total;
  ReconstructStats st;
  st.method = options.method;
  const auto region = mask->GetBufferedRegion();
  const std::array<std::size_t, 3> n{region.GetSize()[0], region.GetSize()[1], region.GetSize()[2]};
  st.image_size = n;
  if (n[0] == 0 || n[1] == 0 || n[2] == 0 || !mask->GetBufferPointer())
    throw PreconditionError("mask: the image has no voxels");

  // Geometry: buffer index b corresponds to ITK index start + b.
  const auto spacing = mask->GetSpacing();
  const auto origin = mask->GetOrigin();
  const auto dir = mask->GetDirection();
  IndexToLps map;
  for (int r = 0; r < 3; ++r) {
    if (!(spacing[r] > 0) || !std::isfinite(spacing[r]))
      throw PreconditionError("mask: spacing must be positive (got " + format_number(spacing[r]) + " along axis " +
                              std::to_string(r) + ")");
    for (int c = 0; c < 3; ++c) map.m[r][c] = dir(r, c) * spacing[c];
  }
  for (int r = 0; r < 3; ++r) {
    map.o[r] = origin[r];
    for (int c = 0; c < 3; ++c) map.o[r] += map.m[r][c] * double(region.GetIndex()[c]);
  }
  const double det = dir(0, 0) * (dir(1, 1) * dir(2, 2) - dir(1, 2) * dir(2, 1)) -
                     dir(0, 1) * (dir(1, 0) * dir(2, 2) - dir(1, 2) * dir(2, 0)) +
                     dir(0, 2) * (dir(1, 0) * dir(2, 1) - dir(1, 1) * dir(2, 0));
  if (!(std::abs(det) > 1e-6)) throw PreconditionError("mask: direction matrix is singular");
  st.direction_flips_orientation = det < 0;

  // 1. Crop to the lumen, pad, extract.
  Stopwatch t;
  const Box box = lumen_box(mask->GetBufferPointer(), n);
  st.lumen_voxels = box.count;
  if (!box.count) throw PreconditionError("mask: no lumen voxels (the mask is empty)");
  for (int a = 0; a < 3; ++a) st.crop_size[a] = box.hi[a] - box.lo[a] + 1;
  TriangleList tris;
  {
    auto img = padded_crop(mask->GetBufferPointer(), n, box);
    int dims[3];
    img->GetDimensions(dims);
    st.mask_euler_6_18 = euler_6_18(static_cast<const unsigned char*>(img->GetScalarPointer()), dims[0], dims[1], dims[2]);
    auto pd = isosurface(img, options.method);
    img = nullptr;
    tris = to_lps(pd, map, st.direction_flips_orientation);
  }
  st.extracted_vertices = tris.points.size();
  st.extracted_faces = tris.triangles.size();
  st.time_extract_s = t.seconds();

  // 2. Verify: closed, manifold, consistently oriented, same topology as the mask.
  t.restart();
  TopologyReport topo = analyze_topology(tris);
  st.surface_euler = topo.euler;
  if (topo.unreferenced_vertices || !topo.closed || !topo.manifold || !topo.consistently_oriented)
    throw Error("reconstruct: the extracted surface is not a closed oriented 2-manifold (" +
                describe_topology_failure(topo) + ")");
  if (topo.euler != 2 * st.mask_euler_6_18)
    throw Error("reconstruct: surface Euler characteristic " + std::to_string(topo.euler) +
                " differs from twice the mask's (6,18) Euler characteristic " + std::to_string(st.mask_euler_6_18));
  st.components_found = topo.components.size();

  // 3. Drop small components (by enclosed volume).
  std::vector<ReconstructComponent> comps;
  const P3 ref = {0.5 * (topo.bbox_min[0] + topo.bbox_max[0]), 0.5 * (topo.bbox_min[1] + topo.bbox_max[1]),
                  0.5 * (topo.bbox_min[2] + topo.bbox_max[2])};
  measure(tris, topo.face_component, topo.components.size(), ref, comps);
  std::vector<char> keep(comps.size());
  for (std::size_t c = 0; c < comps.size(); ++c) {
    comps[c].genus = topo.components[c].genus.value_or(0);
    keep[c] = std::abs(comps[c].volume_mm3) >= options.min_component_volume;
    if (!keep[c]) st.dropped.push_back(comps[c]);
  }
  auto by_volume = [](const ReconstructComponent& a, const ReconstructComponent& b) {
    return std::abs(a.volume_mm3) > std::abs(b.volume_mm3);
  };
  std::sort(st.dropped.begin(), st.dropped.end(), by_volume);
  if (st.dropped.size() == comps.size()) {
    double largest = 0;
    for (const auto& c : comps) largest = std::max(largest, std::abs(c.volume_mm3));
    throw PreconditionError("mask: no lumen component encloses at least " + format_number(options.min_component_volume) +
                            " mm^3 (--min-component-volume; the largest encloses " + format_number(largest) + " mm^3)");
  }
  if (!st.dropped.empty()) {
    std::vector<int> new_id(tris.points.size(), -1);
    TriangleList kept;
    kept.triangles.reserve(tris.triangles.size());
    for (std::size_t f = 0; f < tris.triangles.size(); ++f) {
      if (!keep[std::size_t(topo.face_component[f])]) continue;
      std::array<int, 3> tri;
      for (int k = 0; k < 3; ++k) {
        int& id = new_id[std::size_t(tris.triangles[f][k])];
        if (id < 0) {
          id = int(kept.points.size());
          kept.points.push_back(tris.points[std::size_t(tris.triangles[f][k])]);
        }
        tri[k] = id;
      }
      kept.triangles.push_back(tri);
    }
    tris = std::move(kept);
  }
  topo = TopologyReport{};
  st.time_check_s = t.seconds();

  // 4. Smoothing: windowed sinc moves points only (connectivity, hence topology, unchanged).
  if (options.smoothing_iterations > 0) {
    t.restart();
    VtkMessageCapture capture;
    vtkNew<vtkPoints> pts;
    pts->SetDataTypeToDouble();
    pts->SetNumberOfPoints(vtkIdType(tris.points.size()));
    for (std::size_t i = 0; i < tris.points.size(); ++i) pts->SetPoint(vtkIdType(i), tris.points[i].data());
    vtkNew<vtkCellArray> polys;
    polys->AllocateExact(vtkIdType(tris.triangles.size()), vtkIdType(3 * tris.triangles.size()));
    for (const auto& tri : tris.triangles) {
      const vtkIdType ids[3] = {tri[0], tri[1], tri[2]};
      polys->InsertNextCell(3, ids);
    }
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    pd->SetPolys(polys);
    vtkNew<vtkWindowedSincPolyDataFilter> smooth;
    smooth->SetInputData(pd);
    smooth->SetNumberOfIterations(options.smoothing_iterations);
    smooth->SetPassBand(options.pass_band);
    smooth->NormalizeCoordinatesOn();
    smooth->BoundarySmoothingOff();
    smooth->FeatureEdgeSmoothingOff();
    smooth->NonManifoldSmoothingOff();
    smooth->Update();
    if (!capture.errors().empty()) throw Error("smoothing failed: " + capture.first_problem());
    vtkPoints* out = smooth->GetOutput()->GetPoints();
    if (!out || out->GetNumberOfPoints() != vtkIdType(tris.points.size()))
      throw Error("smoothing failed: the point count changed");
    for (std::size_t i = 0; i < tris.points.size(); ++i) out->GetPoint(vtkIdType(i), tris.points[i].data());
    st.smoothed = true;
    st.time_smooth_s = t.seconds();
  }

  Mesh mesh = to_openmesh(tris);
  tris = TriangleList{};

  // 5. Decimation: OpenMesh's quadric decimater; its collapse test (link condition, no
  // tetrahedron collapse) keeps a closed manifold's topology; normal flips are refused.
  if (options.target_faces > 0 && mesh.n_faces() > std::size_t(options.target_faces)) {
    t.restart();
    using Decimater = OpenMesh::Decimater::McDecimaterT<Mesh>;
    using Quadric = OpenMesh::Decimater::ModQuadricT<Mesh>::Handle;
    using NormalFlip = OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle;
    mesh.request_face_normals();
    mesh.update_face_normals();
    {
      Decimater dec(mesh);
      Quadric hq;
      NormalFlip hn;
      dec.add(hq);
      dec.add(hn);
      dec.module(hn).set_max_normal_deviation(60.0);
      dec.set_samples(8);
      if (!dec.initialize()) throw Error("decimation failed to initialise");
      dec.decimate_to_faces(0, std::size_t(options.target_faces));
    }
    mesh.garbage_collection();
    mesh.release_face_normals();
    st.decimated = true;
    st.time_decimate_s = t.seconds();
  }

  // 6. Final check and statistics.
  t.restart();
  const TopologyReport fin = analyze_topology(mesh);
  if (fin.unreferenced_vertices || !fin.closed || !fin.manifold || !fin.consistently_oriented)
    throw Error("reconstruct: the final surface is not a closed oriented 2-manifold (" + describe_topology_failure(fin) +
                ")");
  std::size_t kept_count = 0;
  int kept_genus = 0;
  for (std::size_t c = 0; c < comps.size(); ++c)
    if (keep[c]) {
      ++kept_count;
      kept_genus += comps[c].genus;
    }
  if (fin.components.size() != kept_count || !fin.genus || *fin.genus != kept_genus)
    throw Error("reconstruct: topology changed after smoothing/decimation (" + std::to_string(fin.components.size()) +
                " components, genus " + (fin.genus ? std::to_string(*fin.genus) : std::string("undefined")) +
                "; expected " + std::to_string(kept_count) + " components, genus " + std::to_string(kept_genus) + ")");
  {
    const TriangleList fl = to_triangle_list(mesh);
    measure(fl, fin.face_component, fin.components.size(), ref, st.kept);
    for (std::size_t c = 0; c < st.kept.size(); ++c) st.kept[c].genus = fin.components[c].genus.value_or(0);
    std::sort(st.kept.begin(), st.kept.end(), by_volume);
  }
  st.vertices = mesh.n_vertices();
  st.faces = mesh.n_faces();
  st.genus = *fin.genus;
  st.time_check_s += t.seconds();
  st.time_total_s = total.seconds();
  if (stats_out) *stats_out = std::move(st);
  return mesh;
}

nlohmann::json BoundaryDistance::to_json() const {
  return {{"max_mm", max_mm}, {"mean_mm", mean_mm}, {"vertices", vertices}, {"far", far}, {"max_spacing_mm", max_spacing_mm}};
}

BoundaryDistance distance_to_mask_boundary(const Mesh& surface, const MaskImage* mask) {
  if (!mask) throw PreconditionError("no mask");
  const auto region = mask->GetBufferedRegion();
  const long n[3] = {long(region.GetSize()[0]), long(region.GetSize()[1]), long(region.GetSize()[2])};
  const unsigned char* d = mask->GetBufferPointer();
  const auto sp = mask->GetSpacing();
  const auto org = mask->GetOrigin();
  const auto dir = mask->GetDirection();
  auto at = [&](long i, long j, long k) -> bool {
    if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) return false;
    return d[(k * n[1] + j) * n[0] + i] != 0;
  };
  BoundaryDistance out;
  out.max_spacing_mm = std::max({sp[0], sp[1], sp[2]});
  const int R = 3;
  double sum = 0;
  for (auto v : surface.vertices()) {
    const auto& p = surface.point(v);
    // Continuous buffer index: x = diag(1/s) D^T (p - origin) - start.
    double x[3];
    for (int a = 0; a < 3; ++a) {
      double t = 0;
      for (int r = 0; r < 3; ++r) t += dir(r, a) * (p[r] - org[r]);
      x[a] = t / sp[a] - double(region.GetIndex()[a]);
    }
    const long c[3] = {std::lround(x[0]), std::lround(x[1]), std::lround(x[2])};
    double best = kInf;
    for (long k = c[2] - R; k <= c[2] + R; ++k)
      for (long j = c[1] - R; j <= c[1] + R; ++j)
        for (long i = c[0] - R; i <= c[0] + R; ++i) {
          if (!at(i, j, k)) continue;
          const long q[3] = {i, j, k};
          for (int a = 0; a < 3; ++a)
            for (int s = -1; s <= 1; s += 2) {
              long nb[3] = {i, j, k};
              nb[a] += s;
              if (at(nb[0], nb[1], nb[2])) continue;
              // The face between q and nb: plane x_a = q_a + s/2, the other two coordinates
              // within half a voxel of q.
              double d2 = 0;
              for (int b = 0; b < 3; ++b) {
                const double e = b == a ? x[b] - (double(q[b]) + 0.5 * s)
                                        : std::max(0.0, std::abs(x[b] - double(q[b])) - 0.5);
                d2 += (e * sp[b]) * (e * sp[b]);
              }
              best = std::min(best, d2);
            }
        }
    ++out.vertices;
    if (!std::isfinite(best)) {
      ++out.far;
      continue;
    }
    const double dd = std::sqrt(best);
    out.max_mm = std::max(out.max_mm, dd);
    sum += dd;
  }
  if (out.vertices > out.far) out.mean_mm = sum / double(out.vertices - out.far);
  return out;
}

}  // namespace cf
