// Ascii PLY read in chunks of lines side by side (ReadContext::loops): the same mesh and report
// as the one-pass reader, on well-formed files and, through the one-pass reader, on files that
// are not one record per line or that have an error.
#include <gtest/gtest.h>

#include <string>

#include "io/formats.h"
#include "io_test_util.h"

namespace parapm {
namespace {

// Chunks of at least 16 bytes: a few lines each.
struct Chunked {
  ChunkedLoops loops{7, 3, 16};
};

void expect_same_read(const std::string& text, const std::string& name = "m.ply") {
  SCOPED_TRACE(name);
  ReadReport one_pass, chunked;
  const Mesh a = read_mesh_from_memory(text, name, &one_pass);
  Chunked c;
  const Mesh b = read_mesh_from_memory(text, name, &chunked, {}, &c.loops);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.face_wedges, b.face_wedges);
  EXPECT_EQ(a.wedge_values, b.wedge_values);
  EXPECT_EQ(a.wedge_vertex, b.wedge_vertex);
  EXPECT_EQ(a.positions_are_float, b.positions_are_float);
  EXPECT_EQ(one_pass.polygons, chunked.polygons);
  EXPECT_EQ(one_pass.triangulated_polygons, chunked.triangulated_polygons);
  EXPECT_EQ(one_pass.welded_vertices, chunked.welded_vertices);
  EXPECT_EQ(one_pass.ignored, chunked.ignored);
}

std::string header(int vertices, int faces, const std::string& vertex_properties) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) + "\n" +
         vertex_properties + "element face " + std::to_string(faces) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

const char* const kXyz = "property float x\nproperty float y\nproperty float z\n";

// A strip of quads (a polygon per record, fan-split), with some vertices at one place (welded).
std::string quad_strip(int quads) {
  std::string v, f;
  for (int i = 0; i <= quads; ++i) {
    v += std::to_string(i) + " 0 0\n" + std::to_string(i) + " 1 0.5\n";
    if (i < quads)
      f += "4 " + std::to_string(2 * i) + " " + std::to_string(2 * i + 2) + " " +
           std::to_string(2 * i + 3) + " " + std::to_string(2 * i + 1) + "\n";
  }
  v += "0 0 0\n";  // at vertex 0's place
  f += "3 " + std::to_string(2 * quads + 2) + " 1 3\n";
  return header(2 * quads + 3, quads + 1, kXyz) + v + f;
}

TEST(PlyChunkedRead, AWrittenMeshWithAttributesReadsTheSame) {
  const Mesh mesh = read_mesh(testing::test_data("pymeshlab-colored-airplane-11k.ply"));
  ASSERT_TRUE(mesh.layout.colors);
  expect_same_read(io::write_ply(mesh, true));
  Chunked c;
  ReadReport report;
  read_mesh_from_memory(io::write_ply(mesh, true), "m.ply", &report, {}, &c.loops);
  EXPECT_GT(c.loops.seconds(), 0) << "the chunks ran";
}

TEST(PlyChunkedRead, PolygonsWeldsAndBlankLinesAtTheEndReadTheSame) {
  expect_same_read(quad_strip(40));
  expect_same_read(quad_strip(40) + "\n\n  \n");
  std::string crlf;
  for (char ch : quad_strip(40)) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
  expect_same_read(crlf);
}

TEST(PlyChunkedRead, FilesNotOneRecordPerLineReadAsTheOnePassReaderReadsThem) {
  std::string two_per_line = quad_strip(40);
  const size_t body = two_per_line.find("end_header\n") + 11;
  two_per_line[two_per_line.find('\n', body + 60)] = ' ';  // two vertices on one line
  expect_same_read(two_per_line);
  std::string blank_inside = quad_strip(40);
  blank_inside.insert(blank_inside.find('\n', body + 100) + 1, 1, '\n');
  expect_same_read(blank_inside);
  expect_same_read(quad_strip(40) + "junk after the faces\n");
}

TEST(PlyChunkedRead, ErrorsAreTheOnePassReadersOwn) {
  std::string bad_index = quad_strip(40);
  bad_index.replace(bad_index.rfind("3 "), 2, "3 999 ");
  std::string message_one_pass, message_chunked;
  try {
    read_mesh_from_memory(bad_index, "m.ply");
  } catch (const Error& e) {
    message_one_pass = e.what();
  }
  Chunked c;
  try {
    read_mesh_from_memory(bad_index, "m.ply", nullptr, {}, &c.loops);
  } catch (const Error& e) {
    message_chunked = e.what();
  }
  EXPECT_NE(message_one_pass.find("vertex index 999"), std::string::npos) << message_one_pass;
  EXPECT_EQ(message_one_pass, message_chunked);
  // A header with two problems: the one-pass reader names the vertex element's first.
  std::string two_problems = quad_strip(40);
  two_problems.replace(two_problems.find("property float x"), 16, "property float w");
  two_problems.replace(two_problems.find("vertex_indices"), 14, "vertex_nidices");
  try {
    read_mesh_from_memory(two_problems, "m.ply", nullptr, {}, &c.loops);
    FAIL() << "read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no scalar 'x' property"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace parapm
