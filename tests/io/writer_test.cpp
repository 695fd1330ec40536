// Writers: read(write(mesh)) gives the same positions bit for bit, the same faces and the same
// attribute values, for OBJ, binary PLY, ascii PLY and their .gz forms, on the committed meshes
// and on small meshes built here; refused meshes and paths.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <iterator>

#include "io/byte_input.h"
#include "io_test_util.h"
#include "test_support.h"

namespace parapm {
namespace {

using testing::expect_error;
using testing::expect_identical;
using testing::expect_same_corners;
using testing::TempDir;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

struct Variant {
  const char* suffix;
  bool ascii;
};
const Variant kVariants[] = {{".obj", false},    {".ply", false},    {".ply", true},
                             {".obj.gz", false}, {".ply.gz", false}, {".ply.gz", true}};

// One wedge per vertex, wedge i on vertex i: what PLY stores as it is.
bool per_vertex_wedges(const Mesh& mesh) {
  if (!mesh.layout.any()) return true;
  if (mesh.wedge_count() != mesh.vertex_count()) return false;
  for (size_t w = 0; w < mesh.wedge_count(); ++w)
    if (mesh.wedge_vertex[w] != w) return false;
  return true;
}

void expect_round_trip(const Mesh& mesh, const std::string& name) {
  TempDir dir;
  for (const Variant& v : kVariants) {
    const std::string path = dir.file(name + (v.ascii ? "-ascii" : "") + v.suffix);
    SCOPED_TRACE(path);
    WriteOptions options;
    options.ascii = v.ascii;
    write_mesh(mesh, path, options);
    const bool gz = std::string(v.suffix).ends_with(".gz");
    EXPECT_EQ(io::is_gzip(slurp(path)), gz);
    ReadReport report;
    const Mesh back = read_mesh(path, &report);
    EXPECT_EQ(report.encoding, v.ascii || std::string(v.suffix).starts_with(".obj")
                                   ? "ascii"
                                   : "binary_little_endian");
    expect_same_corners(mesh, back);
    const bool obj = std::string(v.suffix).starts_with(".obj");
    if (obj || !mesh.layout.any()) {
      // Vertex numbering is kept: same positions, same faces.
      ASSERT_EQ(back.vertex_count(), mesh.vertex_count());
      for (size_t i = 0; i < mesh.vertex_count(); ++i)
        for (int c = 0; c < 3; ++c)
          ASSERT_TRUE(testing::same_bits(back.positions[i][c], mesh.positions[i][c]));
      EXPECT_EQ(back.faces, mesh.faces);
    }
    if (!obj && per_vertex_wedges(mesh)) expect_identical(mesh, back);
  }
}

class CommittedMeshRoundTrip : public ::testing::TestWithParam<const char*> {};

TEST_P(CommittedMeshRoundTrip, EveryWriterReadsBackExactly) {
  const Mesh mesh = read_mesh(testing::test_data(GetParam()));
  ASSERT_GT(mesh.face_count(), 0u);
  expect_round_trip(mesh, GetParam());
}

// binary_ply_size counts what the PLY writer writes, without writing it.
TEST_P(CommittedMeshRoundTrip, BinaryPlySizeIsTheWrittenSize) {
  const Mesh mesh = read_mesh(testing::test_data(GetParam()));
  TempDir dir;
  write_mesh(mesh, dir.file("m.ply"));
  EXPECT_EQ(binary_ply_size(mesh), slurp(dir.file("m.ply")).size());
}

INSTANTIATE_TEST_SUITE_P(TestData, CommittedMeshRoundTrip,
                         ::testing::Values("pymeshlab-bunny-textured-10k.obj",
                                           "pymeshlab-colored-airplane-11k.ply",
                                           "cad-featuretype-3k.stl", "stratocaster-9k.ply",
                                           "cad-cycloidal-43k.ply", "gmsh-aneurysm-20k.stl.gz"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

//  v3 ---- v2      two triangles; v0 and v2 each carry two wedges (a seam along the diagonal),
//   | \ f1  |      every channel present, double positions that are not floats.
//   |  \    |
//   | f0 \  |
//  v0 ---- v1
Mesh seam_mesh() {
  Mesh m;
  m.positions = {{0.1, 0, 0}, {1, 0, 1e-300}, {1, 1.0 / 3.0, 0}, {0, 1, -0.0}};
  m.faces = {{0, 1, 2}, {0, 2, 3}};
  m.layout = {true, true, true};
  m.wedge_vertex = {0, 1, 2, 0, 2, 3};
  m.face_wedges = {{0, 1, 2}, {3, 4, 5}};
  for (int w = 0; w < 6; ++w) {
    // Normal, texcoord per wedge; colour per vertex (OBJ stores colours per vertex).
    const float f = float(w), v = float(m.wedge_vertex[w]);
    const float values[9] = {0, 0, 1, f / 7, 1 - f / 9, v / 10, 1, 0.5f, v == 3 ? 0.2f : 1};
    m.wedge_values.insert(m.wedge_values.end(), values, values + 9);
  }
  m.positions_are_float = false;
  return m;
}

TEST(Writer, SeamsBecomeOnePlyVertexPerWedge) {
  const Mesh mesh = seam_mesh();
  {
    // (Every channel, double positions, wedges: the size counts them as the writer writes.)
    TempDir dir;
    write_mesh(mesh, dir.file("seam.ply"));
    EXPECT_EQ(binary_ply_size(mesh), slurp(dir.file("seam.ply")).size());
  }
  TempDir dir;
  write_mesh(mesh, dir.file("seam.ply"));
  ReadReport report;
  const Mesh back = read_mesh(dir.file("seam.ply"), &report);
  EXPECT_EQ(back.vertex_count(), 6u);  // v0 and v2 twice
  // Vertex by vertex: v0's two wedges, v1, v2's two wedges, v3; the reader welds the second
  // PLY vertices of v0 and v2 onto the first (left unused), each keeping its wedge.
  EXPECT_EQ(report.welded_vertices, 2u);
  EXPECT_EQ(back.faces, (std::vector<Triangle>{{0, 2, 3}, {0, 3, 5}}));
  EXPECT_EQ(back.wedge_vertex, (std::vector<VertexId>{0, 0, 2, 3, 3, 5}));
  expect_same_corners(mesh, back, false);  // colours came from floats: quantised to uchar
  const float* w5 = back.wedge(5);
  EXPECT_EQ(w5[back.layout.color_offset() + 3], float(51 / 255.0));  // 0.2 * 255 = 51
}

TEST(Writer, ObjKeepsAttributesExactly) {
  const Mesh mesh = seam_mesh();
  TempDir dir;
  write_mesh(mesh, dir.file("seam.obj"));
  const Mesh back = read_mesh(dir.file("seam.obj"));
  expect_same_corners(mesh, back);
  EXPECT_FALSE(back.positions_are_float);
  EXPECT_TRUE(testing::same_bits(back.positions[3][2], -0.0));
  // Alpha 0.2 somewhere: colours are written with alpha.
  EXPECT_NE(slurp(dir.file("seam.obj")).find("v 0.1 0 0 0 1 0.5 1\n"), std::string::npos);
}

TEST(Writer, DoublePositionsStayDoubleInPly) {
  Mesh mesh = seam_mesh();
  mesh.layout = {};
  mesh.wedge_vertex.clear();
  mesh.wedge_values.clear();
  mesh.face_wedges.clear();
  expect_round_trip(mesh, "double");
  // A mesh claiming float positions that are not: still written exactly (as double).
  mesh.positions_are_float = true;
  TempDir dir;
  write_mesh(mesh, dir.file("claim.ply"));
  EXPECT_NE(slurp(dir.file("claim.ply")).find("property double x"), std::string::npos);
  EXPECT_EQ(read_mesh(dir.file("claim.ply")).positions, mesh.positions);
}

TEST(Writer, FloatPositionsAreWrittenAsFloat) {
  Mesh mesh = read_mesh(testing::test_data("stratocaster-9k.ply"));
  ASSERT_TRUE(mesh.positions_are_float);
  TempDir dir;
  write_mesh(mesh, dir.file("s.ply"));
  EXPECT_NE(slurp(dir.file("s.ply")).find("property float x"), std::string::npos);
}

TEST(Writer, RefusesOtherFormatsAndInconsistentMeshes) {
  TempDir dir;
  const Mesh good = seam_mesh();
  expect_error([&] { write_mesh(good, dir.file("m.stl")); }, ErrorCode::kInvalidInput,
               {"m.stl", ".obj or .ply"});
  Mesh bad = good;
  bad.faces[1][2] = 7;
  expect_error([&] { write_mesh(bad, dir.file("m.ply")); }, ErrorCode::kInvalidInput,
               {"face 1 has vertex 7"});
  bad = good;
  bad.face_wedges[0][0] = 5;  // a wedge of v3 on a corner of v0
  expect_error([&] { write_mesh(bad, dir.file("m.obj")); }, ErrorCode::kInvalidInput,
               {"face 0 corner 0"});
  bad = good;
  bad.wedge_values.pop_back();
  expect_error([&] { write_mesh(bad, dir.file("m.obj")); }, ErrorCode::kInvalidInput,
               {"wedge_values"});
  expect_error([&] { write_mesh(good, dir.file("no/such/folder/m.obj")); }, ErrorCode::kIo,
               {"m.obj"});
}

}  // namespace
}  // namespace parapm
