#include "colonflat/core/mesh_io.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/Utils/Property.hh>
#include <vtkAlgorithm.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyDataWriter.h>
#include <vtkSmartPointer.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

#include "colonflat/core/atomic_file.h"
#include "colonflat/core/write_errors.h"
#include "colonflat/core/error.h"
#include "colonflat/core/library_output.h"
#include "colonflat/core/memory_budget.h"
#include "colonflat/core/vtk_convert.h"
#include "colonflat/core/vtk_messages.h"
#include "mesh_header_check.h"
#include "mesh_read.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

// Receives what an OpenMesh reader parses, without building a halfedge structure, so that
// non-manifold and broken data reach the diagnosis instead of being silently dropped.
class SoupImporter : public OpenMesh::IO::BaseImporter {
 public:
  SoupImporter(PolygonSoup& soup, fs::path file) : soup_(soup), file_(std::move(file)) {}
  using VH = OpenMesh::VertexHandle;
  using FH = OpenMesh::FaceHandle;
  using HH = OpenMesh::HalfedgeHandle;

  VH add_vertex(const OpenMesh::Vec3f& p) override { return push({p[0], p[1], p[2]}); }
  VH add_vertex(const OpenMesh::Vec3d& p) override { return push({p[0], p[1], p[2]}); }
  VH add_vertex() override { return push({0, 0, 0}); }
  HH add_edge(VH, VH) override { return HH(); }
  FH add_face(const VHandles& ids) override {
    ids_.resize(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i) ids_[i] = ids[i].idx();
    soup_.add_face(ids_.data(), ids_.size());
    return FH(static_cast<int>(soup_.num_faces() - 1));
  }
  FH add_face(HH) override { return FH(); }
  void add_face_texcoords(FH, VH, const std::vector<OpenMesh::Vec2f>&) override {}
  void add_face_texcoords(FH, VH, const std::vector<OpenMesh::Vec3f>&) override {}
  void set_face_texindex(FH, int) override {}
  void set_point(VH v, const OpenMesh::Vec3f& p) override {
    if (v.idx() >= 0 && static_cast<std::size_t>(v.idx()) < soup_.points.size())
      soup_.points[v.idx()] = {p[0], p[1], p[2]};
  }
  void set_halfedge(VH, HH) override {}
  void set_normal(VH, const OpenMesh::Vec3f&) override {}
  void set_normal(VH, const OpenMesh::Vec3d&) override {}
  void set_color(VH, const OpenMesh::Vec3uc&) override {}
  void set_color(VH, const OpenMesh::Vec4uc&) override {}
  void set_color(VH, const OpenMesh::Vec3f&) override {}
  void set_color(VH, const OpenMesh::Vec4f&) override {}
  void set_texcoord(VH, const OpenMesh::Vec2f&) override {}
  void set_status(VH, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_next(HH, HH) override {}
  void set_face(HH, FH) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HH, const OpenMesh::Vec2f&) override {}
  void set_texcoord(VH, const OpenMesh::Vec3f&) override {}
  void set_texcoord(HH, const OpenMesh::Vec3f&) override {}
  void set_status(HH, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec3f&) override {}
  void set_color(OpenMesh::EdgeHandle, const OpenMesh::Vec4f&) override {}
  void set_status(OpenMesh::EdgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_normal(FH, const OpenMesh::Vec3f&) override {}
  void set_normal(FH, const OpenMesh::Vec3d&) override {}
  void set_color(FH, const OpenMesh::Vec3uc&) override {}
  void set_color(FH, const OpenMesh::Vec4uc&) override {}
  void set_color(FH, const OpenMesh::Vec3f&) override {}
  void set_color(FH, const OpenMesh::Vec4f&) override {}
  void set_status(FH, const OpenMesh::Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}
  // Called with the header's counts before any element: the file must be able to hold them (at
  // least 3 bytes a vertex, 4 a face in any format) and they must fit the memory budget.
  void reserve(unsigned int nv, unsigned int, unsigned int nf) override {
    const std::string what = "the header (" + std::to_string(nv) + " vertices, " + std::to_string(nf) + " faces)";
    check_declared_data(file_, what, 3.0 * nv + 4.0 * nf);
    check_memory_budget(file_.string(), what, 120.0 * nv + 120.0 * nf);
    soup_.points.reserve(nv);
    soup_.face_start.reserve(nf + 1);
    soup_.corners.reserve(3ull * nf);
  }
  size_t n_vertices() const override { return soup_.points.size(); }
  size_t n_faces() const override { return soup_.num_faces(); }
  size_t n_edges() const override { return 0; }

 private:
  VH push(const std::array<double, 3>& p) {
    soup_.points.push_back(p);
    return VH(static_cast<int>(soup_.points.size() - 1));
  }
  PolygonSoup& soup_;
  fs::path file_;
  std::vector<std::int64_t> ids_;
};

std::string first_line(std::string s) {
  // VTK messages carry "ERROR: In file, line N\nvtkClass (0x..): text"; keep the text.
  auto pos = s.find("): ");
  if (pos != std::string::npos) s = s.substr(pos + 3);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

PolygonSoup read_vtk_polydata(const fs::path& path, MeshFormat fmt) {
  LibraryOutputCapture printed;  // VTK's logger prints errors to stderr besides the output window
  VtkMessageCapture vtk_messages;
  vtkSmartPointer<vtkPolyData> pd;
  if (fmt == MeshFormat::kVTP) {
    vtkNew<vtkXMLPolyDataReader> r;
    r->SetFileName(path.c_str());
    r->Update();
    if (!vtk_messages.first_problem().empty() || r->GetErrorCode() != 0)
      throw InputError(path.string(), "cannot read VTK XML PolyData: " +
                                          (vtk_messages.first_problem().empty() ? std::string("parse error")
                                                                                : vtk_messages.first_problem()));
    pd = r->GetOutput();
  } else {
    vtkNew<vtkPolyDataReader> r;
    r->SetFileName(path.c_str());
    if (!r->IsFilePolyData())
      throw InputError(path.string(), "not a VTK legacy PolyData file");
    r->Update();
    if (!vtk_messages.first_problem().empty() || r->GetErrorCode() != 0)
      throw InputError(path.string(), "cannot read VTK legacy PolyData: " +
                                          (vtk_messages.first_problem().empty() ? std::string("parse error")
                                                                                : vtk_messages.first_problem()));
    pd = r->GetOutput();
  }
  if (!pd) throw InputError(path.string(), "no PolyData in file");
  return polydata_to_soup(pd);
}

}  // namespace

std::optional<MeshFormat> mesh_format_from_path(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".off") return MeshFormat::kOFF;
  if (ext == ".obj") return MeshFormat::kOBJ;
  if (ext == ".ply") return MeshFormat::kPLY;
  if (ext == ".stl") return MeshFormat::kSTL;
  if (ext == ".vtp") return MeshFormat::kVTP;
  if (ext == ".vtk") return MeshFormat::kVTK;
  return std::nullopt;
}

std::string mesh_format_list() { return ".off .obj .ply .stl .vtp .vtk"; }

PolygonSoup read_polygon_soup(const fs::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(name, "no such file");
  if (fs::is_directory(path, ec)) throw InputError(name, "is a folder, not a mesh file");
  const auto fmt = mesh_format_from_path(path);
  if (!fmt)
    throw InputError(name, "unknown mesh format '" + path.extension().string() + "' (known: " +
                               mesh_format_list() + ")");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(name, "cannot open for reading (permissions?)");
    if (probe.peek() == std::ifstream::traits_type::eof()) throw InputError(name, "empty file");
  }
  check_declared_mesh_size(path, *fmt);
  PolygonSoup soup;
  if (*fmt == MeshFormat::kVTP || *fmt == MeshFormat::kVTK) {
    soup = read_vtk_polydata(path, *fmt);
  } else {
    // A "nan" or "inf" coordinate derails OpenMesh's parsers: named before their consequences.
    check_text_vertex_coordinates(path, *fmt);
    SoupImporter importer(soup, path);
    OpenMesh::IO::Options opt;
    // OpenMesh prints parse problems to its own error stream; capture them for the message.
    std::ostringstream captured;
    omerr().disconnect(std::cerr);
    omerr().connect(captured);
    bool ok = false;
    auto restore = [&] {
      omerr().flush();
      omerr().disconnect(captured);
      omerr().connect(std::cerr);
    };
    try {
      // OpenMesh's PLY reader prints "Unsupported keyword : obj_info" straight to the terminal for
      // the comment lines VTK's PLY writer adds: nothing of that reaches the user.
      LibraryOutputCapture printed;
      ok = OpenMesh::IO::IOManager().read(path.string(), importer, opt);
    } catch (const InputError&) {
      restore();
      throw;
    } catch (const std::exception& e) {
      captured << e.what();
    }
    restore();
    if (!ok) {
      std::string why = first_line(captured.str());
      throw InputError(name, "cannot parse as " + path.extension().string().substr(1) + " file" +
                                 (why.empty() ? std::string("") : ": " + why));
    }
    // OpenMesh's OFF/PLY readers stop quietly at end of file: a truncated file shows up as
    // fewer elements than the header announced, which OpenMesh reports on omerr.
    const std::string warn = captured.str();
    if (warn.find("nexpected end") != std::string::npos || warn.find("runcat") != std::string::npos)
      throw InputError(name, "truncated file: " + first_line(warn));
    if (warn.find("rror") != std::string::npos)  // a reader that skipped what it could not parse
      throw InputError(name, "cannot parse as " + path.extension().string().substr(1) + " file: " + first_line(warn));
  }
  if (soup.points.empty() && soup.num_faces() == 0) throw InputError(name, "empty mesh: no vertices and no faces");
  return soup;
}

LoadedMesh load_mesh(const fs::path& path, const LoadPolicy& policy) { return load_mesh_oriented(path, policy, false); }

LoadedMesh load_mesh_oriented(const fs::path& path, const LoadPolicy& policy, bool outward) {
  PolygonSoup soup = read_polygon_soup(path);
  LoadedMesh out;
  out.diagnosis = diagnose_soup(soup);
  try {
    TriangleList tris = soup_to_triangles(soup, policy, out.diagnosis);
    soup = PolygonSoup();
    TopologyReport topo = analyze_topology(tris);
    add_topology_findings(topo, policy.allow_boundary, out.diagnosis);
    if (!policy.allow_boundary && topo.boundary_edges)
      throw PreconditionError(out.diagnosis.find("boundary_edges")->message + "; a closed surface is required");
    if (!policy.allow_several_components && topo.components.size() > 1)
      throw PreconditionError(std::to_string(topo.components.size()) +
                              " connected components; a single connected surface is required");
    out.orientation = make_orientation_consistent(tris, topo, policy.fix_orientation);
    if (outward) out.orientation.append(orient_outward(tris, topo));
    out.mesh = build_mesh(tris);
    out.topology = topo.inconsistent_edges ? analyze_topology(out.mesh) : std::move(topo);
  } catch (const PreconditionError& e) {
    throw InputError(path.string(), e.what());
  }
  return out;
}

namespace {

MeshFormat writable_format(const fs::path& path) {
  const auto fmt = mesh_format_from_path(path);
  if (!fmt)
    throw UsageError(path.string() + ": unknown mesh format '" + path.extension().string() +
                     "' (known: " + mesh_format_list() + ")");
  return *fmt;
}

// A .vtp (appended, fast compression) or legacy .vtk file of `pd` at `tmp`, tagged with its units
// and space; `path` names the target in the error.
void write_polydata_mesh(vtkPolyData* pd, MeshFormat fmt, const fs::path& tmp, const fs::path& path,
                         const WriteOptions& wo) {
  tag_polydata_space(pd, wo.units, wo.space);
  VtkMessageCapture vtk_messages;
  int ok = 0;
  vtkSmartPointer<vtkAlgorithm> writer;
  if (fmt == MeshFormat::kVTP) {
    vtkNew<vtkXMLPolyDataWriter> w;
    writer = w.GetPointer();
    w->SetFileName(tmp.c_str());
    w->SetInputData(pd);
    use_fast_compression(w);
    ok = w->Write();
  } else {
    vtkNew<vtkPolyDataWriter> w;
    writer = w.GetPointer();
    w->SetFileName(tmp.c_str());
    w->SetInputData(pd);
    if (wo.binary) w->SetFileTypeToBinary();
    else w->SetFileTypeToASCII();
    ok = w->Write();
  }
  if (!ok || !vtk_messages.errors().empty())
    throw Error(path.string() + ": cannot write: " + vtk_messages.write_problem(writer, tmp.string()));
}

bool vtk_format(MeshFormat fmt) { return fmt == MeshFormat::kVTP || fmt == MeshFormat::kVTK; }

}  // namespace

void write_mesh(const Mesh& mesh, const fs::path& path, const WriteOptions& wo) {
  const MeshFormat fmt = writable_format(path);
  write_atomically(path, [&](const fs::path& tmp) {
    if (vtk_format(fmt)) return write_polydata_mesh(mesh_to_polydata(mesh), fmt, tmp, path, wo);
    OpenMesh::IO::Options opt;
    if (wo.binary && (fmt == MeshFormat::kPLY || fmt == MeshFormat::kSTL)) opt += OpenMesh::IO::Options::Binary;
    LibraryOutputCapture printed;  // OpenMesh's writers log "[OBJWriter] : write file"
    if (!OpenMesh::IO::write_mesh(mesh, tmp.string(), opt, static_cast<std::streamsize>(wo.ascii_precision))) {
      const std::string why = file_system_problem(tmp);
      throw Error(path.string() + ": cannot write mesh" + (why.empty() ? "" : ": " + why));
    }
  });
}

void write_mesh(const TriangleList& mesh, const fs::path& path, const WriteOptions& wo) {
  const MeshFormat fmt = writable_format(path);
  if (!vtk_format(fmt)) return write_mesh(build_mesh(mesh), path, wo);
  write_atomically(path, [&](const fs::path& tmp) { write_polydata_mesh(triangles_to_polydata(mesh), fmt, tmp, path, wo); });
}

}  // namespace cf
