// OBJ reader: each statement and corner form, polygons, relative indices, wedges, colours,
// continuations, ignored statements, and malformed files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "io_test_util.h"

namespace parapm {
namespace {

using testing::expect_error;
using testing::read_text;

const std::vector<Triangle> kQuadFan = {{0, 1, 2}, {0, 2, 3}};

//  3---2
//  |   |    one quad, fan-split from its first corner
//  0---1
const char* kQuad =
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 1 1 0\n"
    "v 0 1 0\n";

TEST(ObjReader, QuadIsFanSplitFromItsFirstCorner) {
  ReadReport report;
  const Mesh mesh = read_text(std::string(kQuad) + "f 1 2 3 4\n", "quad.obj", &report);
  EXPECT_EQ(mesh.positions.size(), 4u);
  EXPECT_EQ(mesh.faces, kQuadFan);
  EXPECT_FALSE(mesh.layout.any());
  EXPECT_TRUE(mesh.wedge_vertex.empty());
  EXPECT_TRUE(mesh.face_wedges.empty());
  EXPECT_EQ(report.format, MeshFormat::kObj);
  EXPECT_EQ(report.polygons, 1u);
  EXPECT_EQ(report.triangulated_polygons, 1u);
  EXPECT_TRUE(mesh.positions_are_float);
}

TEST(ObjReader, PentagonGivesThreeTriangles) {
  const Mesh mesh =
      read_text("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n", "penta.obj");
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}, {0, 3, 4}}));
}

TEST(ObjReader, NegativeIndicesCountBackFromTheLastRecord) {
  const Mesh mesh =
      read_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nf -3 -2 -1\nv 0 1 0\nf -4 -2 -1\n", "relative.obj");
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}}));
}

TEST(ObjReader, PositionsKeepDoublePrecision) {
  const Mesh mesh = read_text("v 0.1 -2.5e-3 1e300\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "p.obj");
  EXPECT_EQ(mesh.positions[0][0], 0.1);
  EXPECT_EQ(mesh.positions[0][1], -2.5e-3);
  EXPECT_EQ(mesh.positions[0][2], 1e300);
  EXPECT_FALSE(mesh.positions_are_float);
}

// NaN and infinity parse as numbers, but no mesh can use them: refused where they are, by
// file, line and the vertex's number as the format counts (from 1 in OBJ, from 0 in OFF/PLY).
TEST(ObjReader, NonFinitePositionsAreRefusedWhereTheyAre) {
  expect_error([] { read_text("v 0 0 0\nv 1 0 0\nv nan inf -inf\nf 1 2 3\n", "nan.obj"); },
               ErrorCode::kInvalidInput,
               {"nan.obj", "line 3", "vertex 3 has a non-finite coordinate (nan, inf, -inf)"});
  expect_error([] { read_text("OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", "inf.off"); },
               ErrorCode::kInvalidInput,
               {"inf.off", "line 4", "vertex 1 has a non-finite coordinate"});
  expect_error(
      [] {
        read_text(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
            "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n",
            "nan.ply");
      },
      ErrorCode::kInvalidInput, {"nan.ply", "vertex 2 has a non-finite coordinate"});
}

// Two triangles sharing the edge 0-2; vertex 0 has two texture coordinates (a seam).
TEST(ObjReader, EachDistinctVertexTexcoordNormalTripleIsOneWedgeInFirstUseOrder) {
  ReadReport report;
  const Mesh mesh = read_text(std::string(kQuad) +
                                  "vt 0 0\nvt 1 0\nvt 0.5 1\n"
                                  "vn 0 0 1\n"
                                  "f 1/1/1 2/2/1 3/3/1\n"
                                  "f 1/2/1 3/3/1 4/1/1\n",
                              "wedges.obj", &report);
  EXPECT_EQ(mesh.faces, kQuadFan);
  EXPECT_TRUE(mesh.layout.normals);
  EXPECT_TRUE(mesh.layout.texcoords);
  EXPECT_FALSE(mesh.layout.colors);
  // Wedges: (v1,vt1)=0 (v2,vt2)=1 (v3,vt3)=2 (v1,vt2)=3 (v3,vt3)=2 again, (v4,vt1)=4.
  EXPECT_EQ(mesh.wedge_vertex, (std::vector<VertexId>{0, 1, 2, 0, 3}));
  EXPECT_EQ(mesh.face_wedges, (std::vector<std::array<WedgeId, 3>>{{0, 1, 2}, {3, 2, 4}}));
  ASSERT_EQ(mesh.wedge_values.size(), 5u * 5u);
  const float* w3 = mesh.wedge(3);
  EXPECT_EQ(w3[mesh.layout.normal_offset() + 2], 1.0f);
  EXPECT_EQ(w3[mesh.layout.texcoord_offset()], 1.0f);
  EXPECT_EQ(w3[mesh.layout.texcoord_offset() + 1], 0.0f);
  EXPECT_EQ(mesh.wedge(2)[mesh.layout.texcoord_offset()], 0.5f);
  EXPECT_EQ(report.corners_without_texcoord, 0u);
}

TEST(ObjReader, CornerFormsVertexSlashTexcoordAndDoubleSlashNormal) {
  const Mesh uv =
      read_text(std::string(kQuad) + "vt 0 0\nvt 1 0\nvt 1 1\nf 1/1 2/2 3/3\n", "uv.obj");
  EXPECT_TRUE(uv.layout.texcoords);
  EXPECT_FALSE(uv.layout.normals);
  EXPECT_EQ(uv.wedge_count(), 3u);
  EXPECT_EQ(uv.wedge(2)[1], 1.0f);

  const Mesh n = read_text(std::string(kQuad) + "vn 1 0 0\nvn 0 1 0\nf 1//1 2//2 3//1\n", "n.obj");
  EXPECT_TRUE(n.layout.normals);
  EXPECT_FALSE(n.layout.texcoords);
  EXPECT_EQ(n.wedge_count(), 3u);
  EXPECT_EQ(n.wedge(1)[1], 1.0f);
}

// chair-dupfaces-13k.obj mixes corners with and without vt: they get zero texcoords.
TEST(ObjReader, CornersWithoutTexcoordInATexturedFileGetZeros) {
  ReadReport report;
  const Mesh mesh = read_text(std::string(kQuad) + "vt 0.25 0.75\nf 1/1 2/1 3/1\nf 1 3 4\n",
                              "mixed.obj", &report);
  EXPECT_TRUE(mesh.layout.texcoords);
  EXPECT_EQ(report.corners_without_texcoord, 3u);
  // Vertices 1 and 3 (0 and 2 counting from 0) have two wedges each: with and without vt.
  EXPECT_EQ(mesh.wedge_vertex, (std::vector<VertexId>{0, 1, 2, 0, 2, 3}));
  const float* plain = mesh.wedge(mesh.face_wedges[1][0]);
  EXPECT_EQ(plain[0], 0.0f);
  EXPECT_EQ(plain[1], 0.0f);
  EXPECT_EQ(mesh.wedge(mesh.face_wedges[0][0])[1], 0.75f);
}

TEST(ObjReader, VertexColoursBecomeTheColorChannel) {
  ReadReport report;
  const Mesh mesh =
      read_text("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1 0.5\nv 0 1 0\nf 1 2 3\nf 1 3 4\n",
                "colors.obj", &report);
  ASSERT_TRUE(mesh.layout.colors);
  EXPECT_FALSE(mesh.layout.texcoords);
  // Only colours: one wedge per used vertex, in first-use order.
  EXPECT_EQ(mesh.wedge_vertex, (std::vector<VertexId>{0, 1, 2, 3}));
  const float* c2 = mesh.wedge(2);
  EXPECT_EQ(c2[2], 1.0f);
  EXPECT_EQ(c2[3], 0.5f);
  EXPECT_EQ(mesh.wedge(0)[3], 1.0f);  // alpha defaults to 1
  // Vertex 4 has no colour in a coloured file: opaque white, counted.
  EXPECT_EQ(mesh.wedge(3)[0], 1.0f);
  EXPECT_EQ(report.vertices_without_color, 1u);
}

TEST(ObjReader, VertexWIsIgnoredAndListed) {
  ReadReport report;
  const Mesh mesh = read_text("v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 1\nf 1 2 3\n", "w.obj", &report);
  EXPECT_FALSE(mesh.layout.any());
  EXPECT_NE(std::find(report.ignored.begin(), report.ignored.end(), "obj vertex w coordinates"),
            report.ignored.end());
}

TEST(ObjReader, BackslashContinuesALine) {
  const Mesh mesh = read_text(std::string(kQuad) + "f 1 2 \\\n 3 \\  \r\n4\n", "cont.obj");
  EXPECT_EQ(mesh.faces, kQuadFan);
}

TEST(ObjReader, CommentsBlankLinesAndCrlfAreFine) {
  const Mesh mesh = read_text(
      "# a comment\r\n\r\nv 0 0 0 # trailing\r\nv 1 0 0\r\n\tv 0 1 0\r\nf 1 2 3 # end\r\n",
      "crlf.obj");
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}}));
}

TEST(ObjReader, GroupsObjectsSmoothingAndMaterialsAreListedOnceEach) {
  ReadReport report;
  read_text(std::string("mtllib a.mtl\nmtllib b.mtl\no thing\ng part1\ns 1\nusemtl red\n") + kQuad +
                "f 1 2 3\ng part2\ns off\nusemtl blue\nf 1 3 4\nl 1 2\n",
            "groups.obj", &report);
  std::vector<std::string> expected = {
      "obj material libraries (mtllib)", "obj object names (o)",   "obj groups (g)",
      "obj smoothing groups (s)",        "obj materials (usemtl)", "obj 'l' statements"};
  EXPECT_EQ(report.ignored, expected);
}

TEST(ObjReader, FacesMayReferToVerticesDefinedLater) {
  const Mesh mesh = read_text("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", "forward.obj");
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}}));
}

TEST(ObjReader, IndexOutOfRangeNamesTheLineAndTheIndex) {
  expect_error([] { read_text(std::string(kQuad) + "\nf 1 2 3\nf 1 2 9999\n", "bad.obj"); },
               ErrorCode::kInvalidInput, {"bad.obj: line 7:", "9999", "4 vertex"});
  expect_error([] { read_text(std::string(kQuad) + "f 1/5 2/1 3/1\nvt 0 0\n", "bad.obj"); },
               ErrorCode::kInvalidInput, {"line 5", "texture coordinate index 5"});
  expect_error([] { read_text(std::string(kQuad) + "f 0 1 2\n", "bad.obj"); },
               ErrorCode::kInvalidInput, {"line 5", "index 0"});
  expect_error([] { read_text(std::string(kQuad) + "f -5 1 2\n", "bad.obj"); },
               ErrorCode::kInvalidInput, {"line 5", "-5", "only 4"});
  expect_error([] { read_text(std::string(kQuad) + "f 1 2 99999999999999999999\n", "bad.obj"); },
               ErrorCode::kInvalidInput, {"line 5", "bad face corner"});
}

TEST(ObjReader, MalformedStatementsNameTheLine) {
  expect_error([] { read_text("v 0 0\nv 1 1 1\n", "bad.obj"); }, ErrorCode::kInvalidInput,
               {"line 1", "z coordinate"});
  expect_error([] { read_text("v 0 0 0 1 2\n", "bad.obj"); }, ErrorCode::kInvalidInput,
               {"line 1", "5 values"});
  expect_error([] { read_text("v 0 0 x\n", "bad.obj"); }, ErrorCode::kInvalidInput,
               {"line 1", "'x'"});
  expect_error([] { read_text(std::string(kQuad) + "f 1 2\n", "bad.obj"); },
               ErrorCode::kInvalidInput, {"line 5", "2 corners"});
  expect_error([] { read_text(std::string(kQuad) + "f 1/ 2 3\n", "bad.obj"); },
               ErrorCode::kInvalidInput, {"line 5", "'1/'"});
}

TEST(ObjReader, GarbageIsAnError) {
  expect_error([] { read_text(std::string("\x7f\x45\x4c\x46\x02\x01\x01\0\0\0", 10), "bin.obj"); },
               ErrorCode::kInvalidInput, {"bin.obj: line 1", "not an OBJ statement"});
  expect_error([] { read_text("hello world\nthis is not a mesh\n", "text.obj"); },
               ErrorCode::kInvalidInput, {"text.obj", "not an OBJ file"});
}

TEST(ObjReader, LimitsAreResourceExhausted) {
  ReadLimits limits;
  limits.max_vertices = 3;
  expect_error([&] { read_text(std::string(kQuad) + "f 1 2 3\n", "big.obj", nullptr, limits); },
               ErrorCode::kResourceExhausted, {"limit of 3 vertices"});
  limits = {};
  limits.max_faces = 1;
  expect_error([&] { read_text(std::string(kQuad) + "f 1 2 3 4\n", "big.obj", nullptr, limits); },
               ErrorCode::kResourceExhausted, {"limit of 1 faces"});
}

}  // namespace
}  // namespace parapm
