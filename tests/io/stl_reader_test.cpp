// STL reader: ascii (several solids, polygons, any keyword case) and binary (including a
// header that starts with "solid"), welding, and malformed files.
#include <gtest/gtest.h>

#include "io_test_util.h"

namespace parapm {
namespace {

using testing::Bytes;
using testing::expect_error;
using testing::read_text;

// Two solids: a quad facet (fan-split) and a triangle sharing two corners with it.
const char* kAscii =
    "solid first\n"
    "  facet normal 0 0 1\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 1 0 0\n"
    "      vertex 1 1 0\n"
    "      vertex 0 1 0\n"
    "    endloop\n"
    "  endfacet\n"
    "endsolid first\n"
    "SOLID second\r\n"
    "FACET NORMAL 0 0 1\r\n"
    "OUTER LOOP\r\n"
    "VERTEX 1 1 0\r\n"
    "VERTEX -0 1 0\r\n"  // -0 and 0 are the same coordinate: welded
    "VERTEX 0.5 2 0\r\n"
    "ENDLOOP\r\n"
    "ENDFACET\r\n"
    "ENDSOLID\r\n";

TEST(StlReader, AsciiSolidsPolygonsAndWelding) {
  ReadReport report;
  const Mesh mesh = read_text(kAscii, "two.stl", &report);
  EXPECT_EQ(report.encoding, "ascii");
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}, {2, 3, 4}}));
  EXPECT_EQ(mesh.vertex_count(), 5u);
  EXPECT_EQ(report.welded_vertices, 2u);  // 7 corners, 5 vertices
  EXPECT_EQ(report.polygons, 2u);
  EXPECT_EQ(report.triangulated_polygons, 1u);
  EXPECT_EQ(mesh.positions[4], (Vec3{0.5, 2, 0}));
}

Bytes binary_stl(const std::string& header80, const std::vector<std::array<float, 9>>& tris) {
  Bytes b;
  std::string header = header80;
  header.resize(80, ' ');
  b.text(header).put(uint32_t(tris.size()));
  for (const auto& t : tris) {
    b.put(0.0f).put(0.0f).put(1.0f);
    for (float c : t) b.put(c);
    b.put(uint16_t(0));
  }
  return b;
}

const std::vector<std::array<float, 9>> kTris = {{0, 0, 0, 1, 0, 0, 1, 1, 0},
                                                 {0, 0, 0, 1, 1, 0, 0, 1, 0}};

TEST(StlReader, BinaryWeldsEqualCorners) {
  ReadReport report;
  const Mesh mesh = read_text(binary_stl("binary", kTris).str(), "b.stl", &report);
  EXPECT_EQ(report.encoding, "binary");
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 3}}));
  EXPECT_EQ(mesh.vertex_count(), 4u);
  EXPECT_EQ(report.welded_vertices, 2u);
  EXPECT_TRUE(mesh.positions_are_float);
}

TEST(StlReader, BinaryWhoseHeaderStartsWithSolidIsBinaryWhenTheSizeMatches) {
  ReadReport report;
  const Mesh mesh =
      read_text(binary_stl("solid exported by a CAD tool", kTris).str(), "solid.stl", &report);
  EXPECT_EQ(report.encoding, "binary");
  EXPECT_EQ(mesh.face_count(), 2u);
}

TEST(StlReader, TruncatedBinaryReportsTheSizes) {
  const std::string full = binary_stl("binary", kTris).str();
  expect_error([&] { read_text(full.substr(0, full.size() - 7), "cut.stl"); },
               ErrorCode::kInvalidInput,
               {"cut.stl", "declares 2 triangles", "184 bytes", "177 bytes"});
  expect_error([&] { read_text(full + "xx", "long.stl"); }, ErrorCode::kInvalidInput,
               {"long.stl", "declares 2 triangles", "186 bytes"});
  // Binary data behind a "solid" header, with a wrong size: not taken for ascii.
  const std::string solid = binary_stl("solid x", kTris).str();
  expect_error([&] { read_text(solid.substr(0, solid.size() - 1), "cut.stl"); },
               ErrorCode::kInvalidInput, {"cut.stl", "binary data", "declares 2 triangles"});
  expect_error([] { read_text("tiny", "tiny.stl"); }, ErrorCode::kInvalidInput,
               {"tiny.stl", "too short"});
}

TEST(StlReader, AbsurdBinaryCountIsRefused) {
  Bytes b;
  b.text(std::string(80, ' ')).put(uint32_t(4000000000u));
  expect_error([&] { read_text(b.str(), "huge.stl"); }, ErrorCode::kResourceExhausted,
               {"huge.stl", "4000000000 triangles", "limit"});
  Bytes c;
  c.text(std::string(80, ' ')).put(uint32_t(1000000));
  expect_error([&] { read_text(c.str(), "huge.stl"); }, ErrorCode::kInvalidInput,
               {"huge.stl", "declares 1000000 triangles", "84 bytes"});
}

TEST(StlReader, MalformedAsciiNamesTheLine) {
  expect_error(
      [] {
        read_text("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 oops\n",
                  "bad.stl");
      },
      ErrorCode::kInvalidInput, {"bad.stl: line 5", "'oops'"});
  expect_error(
      [] {
        read_text("solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n",
                  "cut.stl");
      },
      ErrorCode::kInvalidInput, {"cut.stl: line 6", "file ends"});
  expect_error(
      [] {
        read_text(
            "solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
            "endloop\nendfacet\nendsolid\n",
            "two.stl");
      },
      ErrorCode::kInvalidInput, {"two.stl: line 2", "2 vertices"});
  expect_error([] { read_text("solid x\nhello\n", "bad.stl"); }, ErrorCode::kInvalidInput,
               {"bad.stl: line 2", "'hello'"});
}

}  // namespace
}  // namespace parapm
