#include "colonflat/reconstruct/reconstruct.h"

#include <OpenMesh/Tools/Decimater/McDecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <Eigen/Dense>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "colonflat/core/error.h"
#include "colonflat/core/run_stats.h"
#include "colonflat/core/soup.h"
#include "colonflat/core/progress.h"
#include "colonflat/core/topology.h"
#include "colonflat/core/vtk_messages.h"
#include "fairing.h"
#include "reconstruct_internal.h"

namespace cf {

const ParamTable<ReconstructOptions>& reconstruct_param_table() {
  static const ParamTable<ReconstructOptions> table = [](ParamTable<ReconstructOptions> t) {
#define COLONFLAT_PARAMS "colonflat/reconstruct/reconstruct_params.def"
#include "colonflat/core/params_as_rows.h"
    return t;
  }({});
  return table;
}

void validate(const ReconstructOptions& o) {
  reconstruct_param_table().validate(o);
  if (o.method == "discrete-flying-edges" && o.subvoxel != "off")
    throw UsageError("--method discrete-flying-edges extracts labels only: use it with --subvoxel off");
}

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
          {"subvoxel_source", field_source},
          {"fluid_voxels", fluid_voxels},
          {"field_clamped_lumen_voxels", field_clamped_voxels},
          {"smoothing_clamped_vertices", clamped_vertices},
          {"smoothed", smoothed},
          {"fairing_iterations", fairing_iterations},
          {"fairing_energy_before_mm2", fairing_energy_before},
          {"fairing_energy_after_mm2", fairing_energy_after},
          {"fairing_vertices_at_limit", fairing_vertices_at_limit},
          {"decimated", decimated},
          {"vertices", vertices},
          {"faces", faces},
          {"genus", genus},
          {"closed", true},
          {"manifold", true},
          {"units", "mm"},
          {"coordinate_system", "LPS"},
          {"time_field_s", time_field_s},
          {"time_extract_s", time_extract_s},
          {"time_check_s", time_check_s},
          {"time_smooth_s", time_smooth_s},
          {"time_fairing_s", time_fairing_s},
          {"time_decimate_s", time_decimate_s},
          {"time_total_s", time_total_s}};
}

namespace {

using namespace reconstruct_detail;

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

// `t` added to the empty mesh `m` (built in place: an OpenMesh mesh has no move operations, so a
// returned or assigned mesh is copied).
void add_to_openmesh(const TriangleList& t, Mesh& m) {
  m.reserve(t.points.size(), t.points.size() + t.triangles.size(), t.triangles.size());
  for (const auto& p : t.points) m.add_vertex(Vec3(p[0], p[1], p[2]));
  for (const auto& tri : t.triangles) {
    const auto f = m.add_face(Mesh::VertexHandle(tri[0]), Mesh::VertexHandle(tri[1]), Mesh::VertexHandle(tri[2]));
    if (!f.is_valid()) throw Error("reconstruct: internal error: surface triangle rejected by the halfedge mesh");
  }
}


// The steps of reconstruct_surface, sharing the mask's geometry and the surface being built.
class SurfaceReconstruction {
 public:
  // `out`: an empty mesh the surface is built in.
  SurfaceReconstruction(const MaskImage* mask, const CtVoxels& ct, const ReconstructOptions& options, Mesh& out)
      : mask_(mask), ct_(ct), opts_(options), mesh_(out) {}

  void run(ReconstructStats* stats_out) {
    read_geometry();
    check_ct();
    extract();
    phase_done("surface extraction");
    verify_extracted();
    drop_small_components();
    phase_done("topology check, small components");
    smooth_mesh();
    fair_mesh();
    phase_done("smoothing");
    add_to_openmesh(tris_, mesh_);
    tris_ = TriangleList{};
    staircase_ = {};
    decimate();
    final_check();
    phase_done("decimation and final check");
    st_.time_total_s = total_.seconds();
    if (stats_out) *stats_out = std::move(st_);
  }

 private:
  // The index -> LPS map (region start included) and whether it reverses orientation.
  void read_geometry() {
    st_.method = opts_.method;
    const auto region = mask_->GetBufferedRegion();
    size_ = {region.GetSize()[0], region.GetSize()[1], region.GetSize()[2]};
    st_.image_size = size_;
    if (size_[0] == 0 || size_[1] == 0 || size_[2] == 0 || !mask_->GetBufferPointer())
      throw PreconditionError("mask: the image has no voxels");
    const auto spacing = mask_->GetSpacing();
    const auto origin = mask_->GetOrigin();
    const auto dir = mask_->GetDirection();
    for (int r = 0; r < 3; ++r) {
      if (!(spacing[r] > 0) || !std::isfinite(spacing[r]))
        throw PreconditionError("mask: spacing must be positive (got " + format_number(spacing[r]) + " along axis " +
                                std::to_string(r) + ")");
      spacing_[r] = spacing[r];
      for (int c = 0; c < 3; ++c) map_.m[r][c] = dir(r, c) * spacing[c];
    }
    for (int r = 0; r < 3; ++r) {
      map_.o[r] = origin[r];
      for (int c = 0; c < 3; ++c) map_.o[r] += map_.m[r][c] * double(region.GetIndex()[c]);
    }
    const double det = dir(0, 0) * (dir(1, 1) * dir(2, 2) - dir(1, 2) * dir(2, 1)) -
                       dir(0, 1) * (dir(1, 0) * dir(2, 2) - dir(1, 2) * dir(2, 0)) +
                       dir(0, 2) * (dir(1, 0) * dir(2, 1) - dir(1, 1) * dir(2, 0));
    if (!(std::abs(det) > 1e-6)) throw PreconditionError("mask: direction matrix is singular");
    st_.direction_flips_orientation = det < 0;
  }

  // The CT, when used, must be the volume the mask was segmented from: the same voxel grid.
  void check_ct() {
    if (opts_.subvoxel == "ct" && !ct_)
      throw PreconditionError("--subvoxel ct needs the CT (--ct CT, or `colonflat run` on a CT)");
    if (!ct_ || opts_.subvoxel == "mask" || opts_.subvoxel == "off") {
      ct_ = CtVoxels{};
      return;
    }
    const auto region = ct_.image->GetBufferedRegion();
    const auto sp = ct_.image->GetSpacing();
    const auto org = ct_.image->GetOrigin();
    const auto dir = ct_.image->GetDirection(), mask_dir = mask_->GetDirection();
    bool same = ct_.f || ct_.s;
    for (int a = 0; a < 3; ++a) {
      same = same && region.GetSize()[a] == size_[a] && region.GetIndex()[a] == mask_->GetBufferedRegion().GetIndex()[a];
      same = same && std::abs(sp[a] - spacing_[a]) <= 1e-4 * spacing_[a];
      same = same && std::abs(org[a] - mask_->GetOrigin()[a]) <= 1e-3 * spacing_[a];
      for (int c = 0; c < 3; ++c) same = same && std::abs(dir(a, c) - mask_dir(a, c)) <= 1e-4;
    }
    if (!same)
      throw PreconditionError("ct: its voxel grid (size, origin, spacing, direction) differs from the mask's; give the "
                              "CT the mask was segmented from");
  }

  // 1. Crop to the lumen, pad, build the sub-voxel field, extract its isosurface in LPS mm.
  void extract() {
    Stopwatch watch;
    box_ = nonzero_box(mask_->GetBufferPointer(), size_);
    st_.lumen_voxels = box_.count;
    if (!box_.count) throw PreconditionError("mask: no lumen voxels (the mask is empty)");
    for (int a = 0; a < 3; ++a) st_.crop_size[a] = box_.hi[a] - box_.lo[a] + 1;
    auto binary = padded_crop(mask_->GetBufferPointer(), size_, box_);
    int dims[3];
    binary->GetDimensions(dims);
    st_.mask_euler_6_18 =
        euler_6_18(static_cast<const unsigned char*>(binary->GetScalarPointer()), dims[0], dims[1], dims[2]);
    vtkSmartPointer<vtkImageData> source = binary;
    if (opts_.subvoxel != "off" && !ct_ && opts_.mask_smoothing == "sinc") {
      st_.field_source = "mask (sinc)";  // the staircase itself; smoothed and clamped on the mesh
    } else if (opts_.subvoxel != "off") {
      source = subvoxel_field(binary, ct_, box_, spacing_, opts_, st_);
      binary = nullptr;
    }
    auto pd = isosurface(source, opts_.method);
    source = nullptr;
    tris_ = to_lps(pd, map_, st_.direction_flips_orientation);
    if (opts_.subvoxel != "off") staircase_ = staircase_positions(pd, map_);
    st_.extracted_vertices = tris_.points.size();
    st_.extracted_faces = tris_.triangles.size();
    st_.time_extract_s = watch.seconds() - st_.time_field_s;
  }

  // 2. Closed, manifold, consistently oriented, and the topology of the mask.
  void verify_extracted() {
    Stopwatch watch;
    topo_ = analyze_topology(tris_);
    st_.surface_euler = topo_.euler;
    if (topo_.unreferenced_vertices || !topo_.closed || !topo_.manifold || !topo_.consistently_oriented)
      throw Error("reconstruct: the extracted surface is not a closed oriented 2-manifold (" +
                  describe_topology_failure(topo_) + ")");
    if (topo_.euler != 2 * st_.mask_euler_6_18)
      throw Error("reconstruct: surface Euler characteristic " + std::to_string(topo_.euler) +
                  " differs from twice the mask's (6,18) Euler characteristic " + std::to_string(st_.mask_euler_6_18));
    st_.components_found = topo_.components.size();
    ref_ = {0.5 * (topo_.bbox_min[0] + topo_.bbox_max[0]), 0.5 * (topo_.bbox_min[1] + topo_.bbox_max[1]),
            0.5 * (topo_.bbox_min[2] + topo_.bbox_max[2])};
    st_.time_check_s += watch.seconds();
  }

  // 3. Components enclosing less than min_component_volume are dropped (and reported).
  void drop_small_components() {
    Stopwatch watch;
    measure(tris_, topo_.face_component, topo_.components.size(), ref_, comps_);
    keep_.assign(comps_.size(), 0);
    for (std::size_t c = 0; c < comps_.size(); ++c) {
      comps_[c].genus = topo_.components[c].genus.value_or(0);
      keep_[c] = std::abs(comps_[c].volume_mm3) >= opts_.min_component_volume;
      if (!keep_[c]) st_.dropped.push_back(comps_[c]);
    }
    std::sort(st_.dropped.begin(), st_.dropped.end(), by_volume);
    if (st_.dropped.size() == comps_.size()) {
      double largest = 0;
      for (const auto& c : comps_) largest = std::max(largest, std::abs(c.volume_mm3));
      throw PreconditionError("mask: no lumen component encloses at least " + format_number(opts_.min_component_volume) +
                              " mm^3 (--min-component-volume; the largest encloses " + format_number(largest) + " mm^3)");
    }
    if (!st_.dropped.empty()) tris_ = kept_triangles();
    topo_ = TopologyReport{};
    st_.time_check_s += watch.seconds();
  }

  // The triangles of the kept components, with their vertices renumbered (staircase_ too).
  TriangleList kept_triangles() {
    std::vector<int> new_id(tris_.points.size(), -1);
    std::vector<P3> staircase;
    TriangleList kept;
    kept.triangles.reserve(tris_.triangles.size());
    for (std::size_t f = 0; f < tris_.triangles.size(); ++f) {
      if (!keep_[std::size_t(topo_.face_component[f])]) continue;
      std::array<int, 3> tri;
      for (int k = 0; k < 3; ++k) {
        int& id = new_id[std::size_t(tris_.triangles[f][k])];
        if (id < 0) {
          id = int(kept.points.size());
          kept.points.push_back(tris_.points[std::size_t(tris_.triangles[f][k])]);
          if (!staircase_.empty()) staircase.push_back(staircase_[std::size_t(tris_.triangles[f][k])]);
        }
        tri[k] = id;
      }
      kept.triangles.push_back(tri);
    }
    staircase_ = std::move(staircase);
    return kept;
  }

  // 4. Optional windowed-sinc smoothing: moves points only (connectivity, hence topology, unchanged).
  void smooth_mesh() {
    if (opts_.smoothing_iterations <= 0) return;
    Stopwatch watch;
    VtkMessageCapture capture;
    vtkNew<vtkPoints> pts;
    pts->SetDataTypeToDouble();
    pts->SetNumberOfPoints(vtkIdType(tris_.points.size()));
    for (std::size_t i = 0; i < tris_.points.size(); ++i) pts->SetPoint(vtkIdType(i), tris_.points[i].data());
    vtkNew<vtkCellArray> polys;
    polys->AllocateExact(vtkIdType(tris_.triangles.size()), vtkIdType(3 * tris_.triangles.size()));
    for (const auto& tri : tris_.triangles) {
      const vtkIdType ids[3] = {tri[0], tri[1], tri[2]};
      polys->InsertNextCell(3, ids);
    }
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    pd->SetPolys(polys);
    vtkNew<vtkWindowedSincPolyDataFilter> smooth;
    smooth->SetInputData(pd);
    smooth->SetNumberOfIterations(opts_.smoothing_iterations);
    smooth->SetPassBand(opts_.pass_band);
    smooth->NormalizeCoordinatesOn();
    smooth->BoundarySmoothingOff();
    smooth->FeatureEdgeSmoothingOff();
    smooth->NonManifoldSmoothingOff();
    smooth->Update();
    if (!capture.errors().empty()) throw Error("smoothing failed: " + capture.first_problem());
    vtkPoints* out = smooth->GetOutput()->GetPoints();
    if (!out || out->GetNumberOfPoints() != vtkIdType(tris_.points.size()))
      throw Error("smoothing failed: the point count changed");
    for (std::size_t i = 0; i < tris_.points.size(); ++i) out->GetPoint(vtkIdType(i), tris_.points[i].data());
    if (!staircase_.empty()) keep_within_half_voxel();
    st_.smoothed = true;
    st_.time_smooth_s = watch.seconds();
  }

  // 4b. Constrained fairing of a mask-only sub-voxel surface (fairing.h): the smoothest surface
  // within 1/2 voxel of the staircase. Not with a CT: there the vertices already follow the data.
  void fair_mesh() {
    if (opts_.fairing_iterations <= 0 || staircase_.empty() || ct_) return;
    Stopwatch watch;
    FairingOptions options;
    options.iterations = opts_.fairing_iterations;
    const FairingResult r = fair_within_tolerance(tris_, staircase_, lps_to_index(), options);
    st_.fairing_iterations = r.iterations;
    st_.fairing_energy_before = r.energy_before;
    st_.fairing_energy_after = r.energy_after;
    st_.fairing_vertices_at_limit = r.vertices_at_limit;
    st_.time_fairing_s = watch.seconds();
  }

  Eigen::Matrix3d lps_to_index() const {
    Eigen::Matrix3d index_to_lps;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) index_to_lps(r, c) = map_.m[r][c];
    return index_to_lps.inverse();
  }

  // A sub-voxel surface stays within 1/2 voxel (index space) of the staircase: a vertex the
  // smoothing moved farther is pulled back along its displacement.
  void keep_within_half_voxel() {
    const Eigen::Matrix3d lps_to_index = this->lps_to_index();
    const double limit = 0.5 * (1 - 1e-6);
    for (std::size_t i = 0; i < tris_.points.size(); ++i) {
      const Eigen::Vector3d moved(tris_.points[i][0] - staircase_[i][0], tris_.points[i][1] - staircase_[i][1],
                                  tris_.points[i][2] - staircase_[i][2]);
      const double voxels = (lps_to_index * moved).norm();
      if (voxels <= limit) continue;
      ++st_.clamped_vertices;
      for (int a = 0; a < 3; ++a) tris_.points[i][a] = staircase_[i][a] + moved[a] * (limit / voxels);
    }
  }

  // 5. Optional decimation: OpenMesh's quadric decimater; its collapse test (link condition, no
  // tetrahedron collapse) keeps a closed manifold's topology; normal flips are refused.
  void decimate() {
    if (opts_.target_faces <= 0 || mesh_.n_faces() <= std::size_t(opts_.target_faces)) return;
    Stopwatch watch;
    using Decimater = OpenMesh::Decimater::McDecimaterT<Mesh>;
    using Quadric = OpenMesh::Decimater::ModQuadricT<Mesh>::Handle;
    using NormalFlip = OpenMesh::Decimater::ModNormalFlippingT<Mesh>::Handle;
    mesh_.request_face_normals();
    mesh_.update_face_normals();
    {
      Decimater dec(mesh_);
      Quadric hq;
      NormalFlip hn;
      dec.add(hq);
      dec.add(hn);
      dec.module(hn).set_max_normal_deviation(60.0);
      dec.set_samples(8);
      if (!dec.initialize()) throw Error("decimation failed to initialise");
      dec.decimate_to_faces(0, std::size_t(opts_.target_faces));
    }
    mesh_.garbage_collection();
    mesh_.release_face_normals();
    st_.decimated = true;
    st_.time_decimate_s = watch.seconds();
  }

  // 6. The result is a closed oriented manifold with the kept components and their genus.
  void final_check() {
    Stopwatch watch;
    const TopologyReport& fin = *(st_.topology = std::make_shared<TopologyReport>(analyze_topology(mesh_)));
    if (fin.unreferenced_vertices || !fin.closed || !fin.manifold || !fin.consistently_oriented)
      throw Error("reconstruct: the final surface is not a closed oriented 2-manifold (" +
                  describe_topology_failure(fin) + ")");
    std::size_t kept_count = 0;
    int kept_genus = 0;
    for (std::size_t c = 0; c < comps_.size(); ++c)
      if (keep_[c]) {
        ++kept_count;
        kept_genus += comps_[c].genus;
      }
    if (fin.components.size() != kept_count || !fin.genus || *fin.genus != kept_genus)
      throw Error("reconstruct: topology changed after smoothing/decimation (" +
                  std::to_string(fin.components.size()) + " components, genus " +
                  (fin.genus ? std::to_string(*fin.genus) : std::string("undefined")) + "; expected " +
                  std::to_string(kept_count) + " components, genus " + std::to_string(kept_genus) + ")");
    const TriangleList final_triangles = to_triangle_list(mesh_);
    measure(final_triangles, fin.face_component, fin.components.size(), ref_, st_.kept);
    for (std::size_t c = 0; c < st_.kept.size(); ++c) st_.kept[c].genus = fin.components[c].genus.value_or(0);
    std::sort(st_.kept.begin(), st_.kept.end(), by_volume);
    st_.vertices = mesh_.n_vertices();
    st_.faces = mesh_.n_faces();
    st_.genus = *fin.genus;
    st_.time_check_s += watch.seconds();
  }

  static bool by_volume(const ReconstructComponent& a, const ReconstructComponent& b) {
    return std::abs(a.volume_mm3) > std::abs(b.volume_mm3);
  }

  const MaskImage* mask_;
  CtVoxels ct_;
  const ReconstructOptions& opts_;
  ReconstructStats st_;
  Stopwatch total_;
  std::array<std::size_t, 3> size_{0, 0, 0};
  std::array<double, 3> spacing_{1, 1, 1};
  IndexToLps map_{};
  Box box_;
  TriangleList tris_;
  std::vector<P3> staircase_;  // staircase position of each point of tris_ (sub-voxel surfaces only)
  TopologyReport topo_;
  std::vector<ReconstructComponent> comps_;
  std::vector<char> keep_;
  P3 ref_{0, 0, 0};
  Mesh& mesh_;  // the caller's
};

}  // namespace

namespace {
void reconstruct_into(Mesh& out, const MaskImage* mask, const CtVoxels& ct, const ReconstructOptions& options,
                      ReconstructStats* stats) {
  validate(options);
  if (!mask) throw PreconditionError("no mask");
  if (out.n_vertices() != 0 || out.n_faces() != 0) throw PreconditionError("reconstruct: the output mesh is not empty");
  SurfaceReconstruction(mask, ct, options, out).run(stats);
}
}  // namespace

void reconstruct_surface_into(Mesh& out, const MaskImage* mask, const CtImage* ct, const ReconstructOptions& options,
                              ReconstructStats* stats) {
  reconstruct_into(out, mask, ct ? CtVoxels{ct, ct->GetBufferPointer(), nullptr} : CtVoxels{}, options, stats);
}

void reconstruct_surface_into(Mesh& out, const MaskImage* mask, const CompactCtImage* ct,
                              const ReconstructOptions& options, ReconstructStats* stats) {
  reconstruct_into(out, mask, ct ? CtVoxels{ct, nullptr, ct->GetBufferPointer()} : CtVoxels{}, options, stats);
}

Mesh reconstruct_surface(const MaskImage* mask, const CtImage* ct, const ReconstructOptions& options,
                         ReconstructStats* stats) {
  Mesh m;
  reconstruct_surface_into(m, mask, ct, options, stats);
  return m;
}

Mesh reconstruct_surface(const MaskImage* mask, const ReconstructOptions& options, ReconstructStats* stats) {
  return reconstruct_surface(mask, nullptr, options, stats);
}

}  // namespace cf
