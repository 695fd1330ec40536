// PLY read in chunks side by side (ReadContext::loops), ascii by lines and binary by records: the
// same mesh and report as the one-pass reader, on well-formed files and, through the one-pass
// reader, on files that are not one record per line (ascii), not of three indices a face or with
// bytes after the faces (binary), or that have an error.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "io/formats.h"
#include "io_test_util.h"

namespace parapm {
namespace {

// Chunks of at least 16 bytes: a few lines each.
struct Chunked {
  ChunkedLoops loops{7, 3, 16};
};

// Whether the chunked read took the file in chunks (else the one-pass reader read it).
bool expect_same_read(const std::string& text, const std::string& name = "m.ply") {
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
  EXPECT_FALSE(one_pass.read_in_chunks);
  return chunked.read_in_chunks;
}

// The messages the one-pass and the chunked read of `file` fail with (empty: it read).
std::pair<std::string, std::string> error_messages(const std::string& file) {
  std::string one_pass, chunked;
  try {
    read_mesh_from_memory(file, "m.ply");
  } catch (const Error& e) {
    one_pass = e.what();
  }
  Chunked c;
  try {
    read_mesh_from_memory(file, "m.ply", nullptr, {}, &c.loops);
  } catch (const Error& e) {
    chunked = e.what();
  }
  return {one_pass, chunked};
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
  EXPECT_TRUE(expect_same_read(io::write_ply(mesh, true)));
  EXPECT_TRUE(expect_same_read(io::write_ply(mesh, false)));
}

TEST(PlyChunkedRead, PolygonsWeldsAndBlankLinesAtTheEndReadTheSame) {
  EXPECT_TRUE(expect_same_read(quad_strip(40)));
  EXPECT_TRUE(expect_same_read(quad_strip(40) + "\n\n  \n"));
  std::string crlf;
  for (char ch : quad_strip(40)) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
  EXPECT_TRUE(expect_same_read(crlf));
}

// A binary little-endian PLY of float positions and faces of the given index lists (uchar count,
// int indices), with `after` appended.
std::string binary_ply(const std::vector<float>& xyz,
                       const std::vector<std::vector<int32_t>>& faces,
                       const std::string& after = "") {
  std::string out = "ply\nformat binary_little_endian 1.0\nelement vertex " +
                    std::to_string(xyz.size() / 3) + "\n" + kXyz + "element face " +
                    std::to_string(faces.size()) +
                    "\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&](const void* data, size_t bytes) {
    out.append(static_cast<const char*>(data), bytes);
  };
  for (float x : xyz) put(&x, sizeof x);
  for (const auto& face : faces) {
    const auto n = uint8_t(face.size());
    put(&n, 1);
    for (int32_t v : face) put(&v, sizeof v);
  }
  return out + after;
}

// A strip of `quads` quads, each as two triangles, or one quad in the middle as a polygon.
std::string binary_strip(int quads, bool one_polygon) {
  std::vector<float> xyz;
  std::vector<std::vector<int32_t>> faces;
  for (int i = 0; i <= quads; ++i) {
    xyz.insert(xyz.end(), {float(i), 0, 0, float(i), 1, 0.5f});
    if (i == quads) break;
    const int32_t a = 2 * i, b = 2 * i + 2, c = 2 * i + 3, d = 2 * i + 1;
    if (one_polygon && i == quads / 2) {
      faces.push_back({a, b, c, d});
    } else {
      faces.push_back({a, b, c});
      faces.push_back({a, c, d});
    }
  }
  return binary_ply(xyz, faces);
}

TEST(PlyChunkedRead, BinaryFilesReadInChunksOnlyWhereEveryRecordHasItsStride) {
  EXPECT_TRUE(expect_same_read(binary_strip(400, false)));
  // A polygon moves the records after it: read by the one-pass reader.
  EXPECT_FALSE(expect_same_read(binary_strip(400, true)));
  // Bytes after the faces: the one-pass reader notes them.
  EXPECT_FALSE(expect_same_read(binary_strip(400, false) + "junk"));
}

TEST(PlyChunkedRead, BinaryErrorsAreTheOnePassReadersOwn) {
  std::string bad_index = binary_strip(400, false);
  const int32_t far = 99999;
  std::memcpy(bad_index.data() + bad_index.size() - 8, &far, sizeof far);
  const auto [one_pass, chunked] = error_messages(bad_index);
  EXPECT_NE(one_pass.find("vertex index 99999"), std::string::npos) << one_pass;
  EXPECT_EQ(one_pass, chunked);
}

TEST(PlyChunkedRead, FilesNotOneRecordPerLineReadAsTheOnePassReaderReadsThem) {
  std::string two_per_line = quad_strip(40);
  const size_t body = two_per_line.find("end_header\n") + 11;
  two_per_line[two_per_line.find('\n', body + 60)] = ' ';  // two vertices on one line
  EXPECT_FALSE(expect_same_read(two_per_line));
  std::string blank_inside = quad_strip(40);
  blank_inside.insert(blank_inside.find('\n', body + 100) + 1, 1, '\n');
  EXPECT_FALSE(expect_same_read(blank_inside));
  EXPECT_FALSE(expect_same_read(quad_strip(40) + "junk after the faces\n"));
}

TEST(PlyChunkedRead, ErrorsAreTheOnePassReadersOwn) {
  std::string bad_index = quad_strip(40);
  bad_index.replace(bad_index.rfind("3 "), 2, "3 999 ");
  const auto [one_pass, chunked] = error_messages(bad_index);
  EXPECT_NE(one_pass.find("vertex index 999"), std::string::npos) << one_pass;
  EXPECT_EQ(one_pass, chunked);
  Chunked c;
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
