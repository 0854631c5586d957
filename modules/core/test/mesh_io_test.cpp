// Mesh files: every format round-trips through the libraries' readers and writers; bad files
// give one clear InputError naming the file; writes are atomic.
#include <gtest/gtest.h>

#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <vtkLZ4DataCompressor.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "colonflat/core/error.h"
#include "colonflat/core/mesh_io.h"
#include "colonflat/core/synthetic.h"
#include "colonflat/core/vtk_convert.h"
#include "colonflat/testing/temp_dir.h"

namespace fs = std::filesystem;

namespace cf {
namespace {

class MeshIo : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_ = std::make_unique<testing::TempDir>();
    dir_ = tmp_->path();
  }
  fs::path file(const std::string& name) const { return dir_ / name; }
  void write_text(const std::string& name, const std::string& text) const { std::ofstream(file(name)) << text; }
  std::size_t files_in_dir() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
  std::unique_ptr<testing::TempDir> tmp_;
  fs::path dir_;
};

struct FormatCase {
  std::string ext;
  bool binary;
  double tol;  // coordinate tolerance (float formats)
};

// Each format preserves V, F, genus and coordinates (within the format's precision: OpenMesh's
// readers parse coordinates in single precision; .vtp/.vtk keep doubles).
TEST_F(MeshIo, RoundTripEveryFormat) {
  const Mesh m = synthetic::to_mesh(synthetic::torus_chain(2, 3.25, 1.125, 16, 8, 10.0));
  for (const FormatCase& c : {FormatCase{".off", false, 1e-5}, FormatCase{".obj", false, 1e-5},
                              FormatCase{".ply", false, 1e-5}, FormatCase{".ply", true, 1e-5},
                              FormatCase{".stl", false, 1e-5}, FormatCase{".stl", true, 1e-5},
                              FormatCase{".vtp", true, 1e-12}, FormatCase{".vtk", true, 1e-12},
                              FormatCase{".vtk", false, 1e-5}}) {
    const fs::path p = file(std::string("rt") + (c.binary ? "_bin" : "_asc") + c.ext);
    WriteOptions wo;
    wo.binary = c.binary;
    write_mesh(m, p, wo);
    LoadedMesh back = load_mesh(p);
    SCOPED_TRACE(p.string());
    EXPECT_EQ(back.mesh.n_vertices(), m.n_vertices());
    EXPECT_EQ(back.mesh.n_faces(), m.n_faces());
    EXPECT_EQ(back.topology.genus, 2);
    EXPECT_TRUE(back.topology.closed);
    EXPECT_TRUE(back.topology.consistently_oriented);
    if (c.ext != ".stl") {  // STL has no shared vertices: the reader merges them in its own order
      double err = 0;
      for (auto v : m.vertices()) err = std::max(err, (m.point(v) - back.mesh.point(v)).norm());
      EXPECT_LT(err, c.tol);
    }
  }
}

// .vtp output records units and coordinate system in field data.
TEST_F(MeshIo, VtpRecordsUnitsAndSpace) {
  write_mesh(synthetic::to_mesh(synthetic::sphere(1, 8, 4)), file("s.vtp"));
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(file("s.vtp").c_str());
  r->Update();
  auto* units = vtkStringArray::SafeDownCast(r->GetOutput()->GetFieldData()->GetAbstractArray("Units"));
  auto* space = vtkStringArray::SafeDownCast(r->GetOutput()->GetFieldData()->GetAbstractArray("CoordinateSystem"));
  ASSERT_NE(units, nullptr);
  ASSERT_NE(space, nullptr);
  EXPECT_EQ(units->GetValue(0), "mm");
  EXPECT_EQ(space->GetValue(0), "LPS");
}

// Every .vtp is appended raw binary in LZ4 blocks (use_fast_compression), a written mesh file says
// so in its header, and it reads back with the same points and triangles.
TEST_F(MeshIo, VtpIsAppendedRawLz4) {
  vtkNew<vtkXMLPolyDataWriter> w;
  use_fast_compression(w);
  EXPECT_EQ(w->GetDataMode(), vtkXMLWriter::Appended);
  EXPECT_FALSE(w->GetEncodeAppendedData());
  EXPECT_NE(vtkLZ4DataCompressor::SafeDownCast(w->GetCompressor()), nullptr);
  const Mesh m = synthetic::to_mesh(synthetic::sphere(1, 8, 4));
  write_mesh(m, file("s.vtp"));
  std::ifstream in(file("s.vtp"));
  std::string line, text;
  while (std::getline(in, line) && line.find("<AppendedData") == std::string::npos) text += line + "\n";
  EXPECT_NE(text.find("compressor=\"vtkLZ4DataCompressor\""), std::string::npos) << text;
  EXPECT_NE(line.find("encoding=\"raw\""), std::string::npos) << line;
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(file("s.vtp").c_str());
  r->Update();
  vtkPolyData* back = r->GetOutput();
  ASSERT_EQ(back->GetNumberOfPoints(), vtkIdType(m.n_vertices()));
  ASSERT_EQ(back->GetNumberOfPolys(), vtkIdType(m.n_faces()));
  for (const auto v : m.vertices())
    for (int k = 0; k < 3; ++k) EXPECT_EQ(back->GetPoint(v.idx())[k], m.point(v)[k]) << v.idx();
}

// A missing file is an InputError that names the file.
TEST_F(MeshIo, MissingFile) {
  try {
    read_polygon_soup(file("nope.off"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file("nope.off").string());
    EXPECT_EQ(e.problem(), "no such file");
    EXPECT_EQ(e.exit_code(), kExitBadInput);
  }
}

// An unknown extension lists the known formats.
TEST_F(MeshIo, UnknownFormat) {
  write_text("m.xyz", "1 2 3\n");
  try {
    read_polygon_soup(file("m.xyz"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(e.problem().find("unknown mesh format '.xyz'"), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find(".vtp"), std::string::npos);
  }
}

// Empty, garbage and truncated files are InputErrors, never crashes.
TEST_F(MeshIo, EmptyGarbageAndTruncatedFiles) {
  write_text("empty.off", "");
  EXPECT_THROW(read_polygon_soup(file("empty.off")), InputError);
  write_text("garbage.off", "this is not a mesh\n\x01\x02\x03");
  EXPECT_THROW(read_polygon_soup(file("garbage.off")), InputError);
  write_text("garbage.vtp", "<VTKFile type='PolyData'><oops");
  EXPECT_THROW(read_polygon_soup(file("garbage.vtp")), InputError);
  write_text("garbage.vtk", "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1\n");
  EXPECT_THROW(read_polygon_soup(file("garbage.vtk")), InputError);
  // OFF announcing 4 vertices and 4 faces, cut after two faces.
  write_text("trunc.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n");
  EXPECT_THROW(load_mesh(file("trunc.off")), InputError);
}

// A folder is not a mesh file.
TEST_F(MeshIo, FolderIsRefused) {
  fs::create_directories(file("d.off"));
  EXPECT_THROW(read_polygon_soup(file("d.off")), InputError);
}

// Out-of-range indices in an OFF file are reported, not crashed on.
TEST_F(MeshIo, OutOfRangeIndexInFile) {
  write_text("oor.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  try {
    load_mesh(file("oor.off"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("outside"), std::string::npos) << e.what();
  }
}

// A vertex with a nan or inf coordinate in a text mesh (OFF, OBJ, ASCII PLY) is named with its
// coordinate, not reported through what the parser read out of step after it (faces out of range).
TEST_F(MeshIo, NonFiniteVertexInTextFileIsNamed) {
  const std::string tet_faces = "3 0 1 2\n3 0 3 1\n3 1 3 2\n3 2 3 0\n";
  write_text("nan.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 nan 1\n" + tet_faces);
  write_text("inf.off", "OFF 4 4 0\n0 0 0\n1 0 -inf\n0 1 0\n0 0 1\n" + tet_faces);
  write_text("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 NaN\nf 1 2 3\nf 1 4 2\nf 2 4 3\nf 3 4 1\n");
  write_text("nan.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                        "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                        "0 0 0\n1 0 0\ninf 1 0\n0 0 1\n" + tet_faces);
  for (const auto& [name, words] : std::vector<std::pair<std::string, std::string>>{
           {"nan.off", "vertex 3 has a coordinate that is not a finite number: y = nan"},
           {"inf.off", "vertex 1 has a coordinate that is not a finite number: z = -inf"},
           {"nan.obj", "vertex 3 has a coordinate that is not a finite number: z = NaN"},
           {"nan.ply", "vertex 2 has a coordinate that is not a finite number: x = inf"}}) {
    try {
      load_mesh(file(name));
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), file(name).string() + ": " + words);
    }
  }
}

// A VTK file (binary doubles) holding a NaN vertex names the vertex and the coordinate too.
TEST_F(MeshIo, NonFiniteVertexInVtpIsNamed) {
  Mesh m = synthetic::to_mesh(synthetic::sphere(1, 8, 4));
  m.set_point(Mesh::VertexHandle(5), Mesh::Point(0, std::numeric_limits<double>::quiet_NaN(), 0));
  write_mesh(m, file("nan.vtp"));
  try {
    load_mesh(file("nan.vtp"));
    FAIL() << "read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 5: y = nan"), std::string::npos) << e.what();
  }
}

// A failed write leaves an existing target untouched and no temporary behind.
TEST_F(MeshIo, FailedWriteLeavesTargetUntouched) {
  write_text("keep.off", "original");
  Mesh empty_mesh;
  const Mesh m = synthetic::to_mesh(synthetic::sphere(1, 8, 4));
  EXPECT_THROW(write_mesh(m, file("keep.unknown")), UsageError);
  fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
  if (::geteuid() != 0) {  // root ignores permissions
    EXPECT_THROW(write_mesh(m, file("keep.off")), Error);
  }
  fs::permissions(dir_, fs::perms::owner_all);
  std::ifstream in(file("keep.off"));
  std::string s;
  std::getline(in, s);
  EXPECT_EQ(s, "original");
  EXPECT_EQ(files_in_dir(), 1u);
}

// A successful write replaces the target and leaves no temporary file.
TEST_F(MeshIo, WriteReplacesAtomically) {
  write_text("m.ply", "old");
  write_mesh(synthetic::to_mesh(synthetic::sphere(1, 8, 4)), file("m.ply"));
  EXPECT_EQ(files_in_dir(), 1u);
  EXPECT_EQ(load_mesh(file("m.ply")).topology.genus, 0);
}

}  // namespace
}  // namespace cf
