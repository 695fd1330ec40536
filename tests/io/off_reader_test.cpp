// OFF reader: header variants, comments, polygons, ignored colours, malformed files.
#include <gtest/gtest.h>

#include "io_test_util.h"

namespace parapm {
namespace {

using testing::expect_error;
using testing::read_text;

//  3---2
//  |   |   a quad (fan-split) and a triangle over it
//  0---1
const std::vector<Triangle> kFaces = {{0, 1, 2}, {0, 2, 3}, {1, 2, 3}};

TEST(OffReader, PlainOffWithCommentsAndAPolygon) {
  ReadReport report;
  const Mesh mesh = read_text(
      "OFF\n# a comment\n4 2 0\n\n0 0 0\n1 0 0 # trailing comment\n1 1 0\n0 1 0\n"
      "4 0 1 2 3\n3 1 2 3\n",
      "quad.off", &report);
  EXPECT_EQ(mesh.positions[2], (Vec3{1, 1, 0}));
  EXPECT_EQ(mesh.faces, kFaces);
  EXPECT_EQ(report.format, MeshFormat::kOff);
  EXPECT_EQ(report.polygons, 2u);
  EXPECT_EQ(report.triangulated_polygons, 1u);
  EXPECT_TRUE(report.ignored.empty());
  EXPECT_FALSE(mesh.layout.any());
}

TEST(OffReader, CountsOnTheHeaderLineAndCrlf) {
  const Mesh mesh = read_text(
      "OFF 4 2 5\r\n0 0 0\r\n1 0 0\r\n1 1 0\r\n0 1 0\r\n4 0 1 2 3\r\n3 1 2 3\r\n", "crlf.off");
  EXPECT_EQ(mesh.faces, kFaces);
}

TEST(OffReader, ColourAndNormalVariantsSkipTheirExtraValues) {
  for (const std::string keyword : {"COFF", "NOFF", "CNOFF", "STOFF", "STCNOFF"}) {
    SCOPED_TRACE(keyword);
    ReadReport report;
    const Mesh mesh = read_text(keyword +
                                    "\n4 2 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n1 1 0 1 0 0 1\n"
                                    "0 1 0 1 0 0 1\n4 0 1 2 3 255 0 0\n3 1 2 3 0.5 0.5 0.5 1\n",
                                "c.off", &report);
    EXPECT_EQ(mesh.faces, kFaces);
    EXPECT_EQ(mesh.positions[3], (Vec3{0, 1, 0}));
    EXPECT_FALSE(report.ignored.empty());
  }
}

TEST(OffReader, ErrorsNameTheLine) {
  const std::string head = "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n";
  expect_error([&] { read_text(head + "4 0 1 2 3\n3 1 2 4\n", "bad.off"); },
               ErrorCode::kInvalidInput,
               {"bad.off: line 8: face 1 has vertex index 4 but the file has 4 vertices"});
  expect_error([&] { read_text(head + "4 0 1 2 3\n3 1 -2 3\n", "bad.off"); },
               ErrorCode::kInvalidInput, {"line 8", "index -2"});
  expect_error([&] { read_text(head + "4 0 1 2 3\n3 1 2\n", "bad.off"); }, ErrorCode::kInvalidInput,
               {"line 8", "declares 3 vertices but the line has 2"});
  expect_error([&] { read_text(head + "4 0 1 2 3\n2 1 2\n", "bad.off"); }, ErrorCode::kInvalidInput,
               {"line 8", "2 vertices"});
  // (A comment pads these past the minimum size the counts need, which is checked first.)
  const std::string padding = "# " + std::string(60, '-') + "\n";
  expect_error([&] { read_text(head + "4 0 1 2 3\n" + padding, "short.off"); },
               ErrorCode::kInvalidInput, {"short.off: line 9", "after 1 of 2 faces"});
  expect_error([&] { read_text("OFF\n4 2 0\n0 0 0\n1 0 zero\n" + padding, "bad.off"); },
               ErrorCode::kInvalidInput, {"line 4", "'zero'"});
  expect_error([&] { read_text(head + "4 0 1 2 3\n", "short.off"); }, ErrorCode::kInvalidInput,
               {"short.off: line 2", "declares 4 vertices and 2 faces but only 35 bytes follow"});
  expect_error([&] { read_text("4OFF\n1 0 0\n0 0 0 1\n", "bad.off"); }, ErrorCode::kInvalidInput,
               {"line 1", "3D"});
  expect_error([&] { read_text("OFF BINARY\n", "bad.off"); }, ErrorCode::kInvalidInput,
               {"binary OFF"});
  expect_error([&] { read_text("PFF\n3 1 0\n", "bad.off"); }, ErrorCode::kInvalidInput,
               {"not an OFF file"});
  expect_error([&] { read_text("OFF\n", "bad.off"); }, ErrorCode::kInvalidInput,
               {"ends before the OFF counts"});
}

TEST(OffReader, AbsurdCountsFailBeforeAllocating) {
  expect_error([] { read_text("OFF\n1000000000000 1 0\n0 0 0\n", "huge.off"); },
               ErrorCode::kResourceExhausted, {"huge.off", "1000000000000 vertices", "limit"});
  expect_error([] { read_text("OFF\n100000000 100000000 0\n0 0 0\n", "huge.off"); },
               ErrorCode::kInvalidInput,
               {"huge.off: line 2", "100000000 vertices", "bytes follow"});
}

}  // namespace
}  // namespace parapm
