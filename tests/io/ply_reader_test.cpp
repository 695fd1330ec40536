// PLY reader: the three encodings, every property type, attributes, face lists, triangle
// strips, skipped elements, and malformed or hostile headers and bodies.
#include <gtest/gtest.h>

#include <algorithm>

#include "io_test_util.h"

namespace parapm {
namespace {

using testing::Bytes;
using testing::expect_error;
using testing::expect_identical;
using testing::read_text;

bool listed(const ReadReport& report, const std::string& what) {
  return std::find(report.ignored.begin(), report.ignored.end(), what) != report.ignored.end();
}

//  3---2
//  |  /|   a quad face (0,1,2,3) and a triangle (0,2,3) over it: three triangles,
//  | / |   vertex colours, a skipped vertex scalar and list, an "edge" element with a list
//  0---1   between the vertices and the faces, a skipped face property.
const char* kHeader =
    "element vertex 4\n"
    "property double x\n"
    "property double y\n"
    "property double z\n"
    "property uchar red\n"
    "property uchar green\n"
    "property uchar blue\n"
    "property short confidence\n"
    "property list uchar int16 extra\n"
    "element edge 2\n"
    "property list ushort uint vertex_list\n"
    "property float weight\n"
    "element face 2\n"
    "property list uchar uint vertex_indices\n"
    "property char flags\n"
    "end_header\n";
const double kX[4] = {0, 1, 1, 0}, kY[4] = {0, 0, 1, 1};
const uint8_t kRed[4] = {0, 255, 128, 7};
const std::vector<Triangle> kFaces = {{0, 1, 2}, {0, 2, 3}, {0, 2, 3}};

std::string binary_ply(bool big_endian) {
  Bytes b(big_endian);
  b.text("ply\nformat ").text(big_endian ? "binary_big_endian" : "binary_little_endian");
  b.text(" 1.0\ncomment test file\n").text(kHeader);
  for (int v = 0; v < 4; ++v) {
    b.put(kX[v]).put(kY[v]).put(0.25 * v);
    b.put(kRed[v]).put(uint8_t(0)).put(uint8_t(255));
    b.put(int16_t(-v));
    b.put(uint8_t(v % 3));
    for (int i = 0; i < v % 3; ++i) b.put(int16_t(i));
  }
  b.put(uint16_t(2)).put(uint32_t(0)).put(uint32_t(1)).put(1.5f);
  b.put(uint16_t(0)).put(2.5f);
  b.put(uint8_t(4)).put(uint32_t(0)).put(uint32_t(1)).put(uint32_t(2)).put(uint32_t(3));
  b.put(int8_t(-1));
  b.put(uint8_t(3)).put(uint32_t(0)).put(uint32_t(2)).put(uint32_t(3)).put(int8_t(1));
  return b.str();
}

const char* kAsciiBody =
    "0 0 0 0 0 255 0 0\n"
    "1 0 0.25 255 0 255 -1 1 0\n"
    "1 1 0.5 128 0 255 -2 2 0 1\n"
    "0 1 0.75 7 0 255 -3 0\n"
    "2 0 1 1.5\n"
    "0 2.5\n"
    "4 0 1 2 3 -1\n"
    "3 0 2 3 1\n";

void expect_test_mesh(const Mesh& mesh) {
  ASSERT_EQ(mesh.vertex_count(), 4u);
  for (int v = 0; v < 4; ++v) EXPECT_EQ(mesh.positions[v], (Vec3{kX[v], kY[v], 0.25 * v}));
  EXPECT_EQ(mesh.faces, kFaces);
  EXPECT_TRUE(mesh.layout.colors);
  EXPECT_FALSE(mesh.layout.normals);
  EXPECT_FALSE(mesh.layout.texcoords);
  // Per-vertex attributes: wedge i is vertex i, face_wedges are the faces.
  EXPECT_EQ(mesh.wedge_vertex, (std::vector<VertexId>{0, 1, 2, 3}));
  ASSERT_EQ(mesh.face_wedges.size(), 3u);
  for (size_t f = 0; f < 3; ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(mesh.face_wedges[f][k], mesh.faces[f][k]);
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(mesh.wedge(v)[0], float(kRed[v] / 255.0));
    EXPECT_EQ(mesh.wedge(v)[1], 0.0f);
    EXPECT_EQ(mesh.wedge(v)[2], 1.0f);
    EXPECT_EQ(mesh.wedge(v)[3], 1.0f);  // no alpha: opaque
  }
}

TEST(PlyReader, BinaryLittleEndian) {
  ReadReport report;
  const Mesh mesh = read_text(binary_ply(false), "le.ply", &report);
  expect_test_mesh(mesh);
  EXPECT_EQ(report.encoding, "binary_little_endian");
  EXPECT_EQ(report.polygons, 2u);
  EXPECT_EQ(report.triangulated_polygons, 1u);
  EXPECT_TRUE(listed(report, "ply vertex property 'confidence'"));
  EXPECT_TRUE(listed(report, "ply vertex property 'extra'"));
  EXPECT_TRUE(listed(report, "ply element 'edge'"));
  EXPECT_TRUE(listed(report, "ply face property 'flags'"));
  EXPECT_TRUE(mesh.positions_are_float);  // stored as double, but every value is a float
}

TEST(PlyReader, BinaryBigEndianReadsTheSameMesh) {
  ReadReport report;
  const Mesh big = read_text(binary_ply(true), "be.ply", &report);
  EXPECT_EQ(report.encoding, "binary_big_endian");
  expect_test_mesh(big);
  expect_identical(big, read_text(binary_ply(false), "le.ply"));
}

TEST(PlyReader, AsciiReadsTheSameMesh) {
  ReadReport report;
  const Mesh mesh =
      read_text(std::string("ply\nformat ascii 1.0\n") + kHeader + kAsciiBody, "a.ply", &report);
  EXPECT_EQ(report.encoding, "ascii");
  expect_test_mesh(mesh);
  expect_identical(mesh, read_text(binary_ply(false), "le.ply"));
}

TEST(PlyReader, EveryPropertyTypeNameReadsInBinary) {
  const char* types[] = {"char",  "uchar",  "short",   "ushort", "int",   "uint",
                         "float", "double", "int8",    "uint8",  "int16", "uint16",
                         "int32", "uint32", "float32", "float64"};
  const int sizes[] = {1, 1, 2, 2, 4, 4, 4, 8, 1, 1, 2, 2, 4, 4, 4, 8};
  for (bool big : {false, true}) {
    Bytes b(big);
    b.text("ply\nformat ").text(big ? "binary_big_endian" : "binary_little_endian").text(" 1.0\n");
    b.text("element vertex 3\n");
    for (const char* t : types) b.text(std::string("property ") + t + " p_" + t + "\n");
    b.text("property int16 x\nproperty float32 y\nproperty uint8 z\n");
    b.text("element face 1\nproperty list ushort int8 vertex_index\nend_header\n");
    for (int v = 0; v < 3; ++v) {
      for (int i = 0; i < 16; ++i)
        for (int k = 0; k < sizes[i]; ++k) b.put(uint8_t(0xA5));
      b.put(int16_t(-300 + v)).put(0.5f * float(v)).put(uint8_t(200 + v));
    }
    b.put(uint16_t(3)).put(int8_t(2)).put(int8_t(1)).put(int8_t(0));
    ReadReport report;
    const Mesh mesh = read_text(b.str(), "types.ply", &report);
    ASSERT_EQ(mesh.vertex_count(), 3u);
    EXPECT_EQ(mesh.positions[2], (Vec3{-298, 1.0, 202}));
    EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{2, 1, 0}}));
    EXPECT_TRUE(mesh.positions_are_float);
    EXPECT_EQ(report.ignored.size(), 16u);
  }
}

TEST(PlyReader, NormalsTexcoordsAndColoursInEveryNaming) {
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  for (const auto& [s, t] : std::vector<std::pair<std::string, std::string>>{
           {"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}}) {
    const std::string text = "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
                             "property float nx\nproperty float ny\nproperty float nz\n"
                             "property float " +
                             s + "\nproperty float " + t +
                             "\n"
                             "property float red\nproperty float green\nproperty float blue\n"
                             "property float alpha\n" +
                             faces +
                             "0 0 0 0 0 1 0.5 0.25 0.1 0.2 0.3 0.4\n"
                             "1 0 0 0 1 0 1 1 1 1 1 1\n"
                             "0 1 0 1 0 0 0 0 0 0 0 0\n"
                             "3 0 1 2\n";
    const Mesh mesh = read_text(text, "attr.ply");
    SCOPED_TRACE(s);
    ASSERT_TRUE(mesh.layout.normals);
    ASSERT_TRUE(mesh.layout.texcoords);
    ASSERT_TRUE(mesh.layout.colors);
    const float* w = mesh.wedge(0);
    EXPECT_EQ(w[mesh.layout.normal_offset() + 2], 1.0f);
    EXPECT_EQ(w[mesh.layout.texcoord_offset()], 0.5f);
    EXPECT_EQ(w[mesh.layout.texcoord_offset() + 1], 0.25f);
    EXPECT_EQ(w[mesh.layout.color_offset()], 0.1f);  // float colours are kept as they are
    EXPECT_EQ(w[mesh.layout.color_offset() + 3], 0.4f);
  }
}

TEST(PlyReader, AsciiFloatPropertiesReadAsFloat32) {
  // "0.1" as a float property is the float32 nearest 0.1, not the double 0.1.
  const Mesh mesh = read_text(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property double z\nend_header\n0.1 0.2 0.1\n",
      "f.ply");
  EXPECT_EQ(mesh.positions[0][0], double(0.1f));
  EXPECT_EQ(mesh.positions[0][2], 0.1);
}

TEST(PlyReader, HeaderWithCrlfAndUnknownLinesIsAccepted) {
  ReadReport report;
  Bytes b;
  b.text("ply\r\nformat binary_little_endian 1.0\r\nCreated by a tool\r\nobj_info x\r\n")
      .text("element vertex 3\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n")
      .text("element face 1\r\nproperty list uchar int vertex_indices\r\nend_header\r\n");
  for (int v = 0; v < 3; ++v) b.put(float(v)).put(13.0f).put(10.0f);
  b.put(uint8_t(3)).put(int32_t(0)).put(int32_t(1)).put(int32_t(2));
  const Mesh mesh = read_text(b.str(), "crlf.ply", &report);
  EXPECT_EQ(mesh.positions[2], (Vec3{2, 13, 10}));
  EXPECT_EQ(mesh.face_count(), 1u);
  EXPECT_TRUE(listed(report, "ply header line 'Created by a tool'"));
}

// A strip a b c d gives (a,b,c) then (c,b,d): odd triangles are flipped so that all face the
// same way. Repeated indices join strips (degenerate triangles, dropped); -1 restarts.
//
//   1---3---5        strip 0 1 2 3 3 4 4 5 6 -1 7 8 9
//   |\  |\  |        j=0 (0,1,2)   j=1 (2,1,3)   j=2..5 degenerate (3 3 / 4 4)
//   | \ | \ |        j=6 (4,5,6)   restart: (7,8,9)
//   0---2---4 ...
TEST(PlyReader, TriangleStripsAlternateOrientationAndDropDegenerateJoints) {
  const std::string header =
      "element vertex 10\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n";
  std::string ascii = "ply\nformat ascii 1.0\n" + header;
  for (int v = 0; v < 10; ++v) ascii += std::to_string(v) + " 0 0\n";
  ascii += "13 0 1 2 3 3 4 4 5 6 -1 7 8 9\n";
  const std::vector<Triangle> expected = {{0, 1, 2}, {2, 1, 3}, {4, 5, 6}, {7, 8, 9}};

  ReadReport report;
  const Mesh mesh = read_text(ascii, "strips.ply", &report);
  EXPECT_EQ(mesh.faces, expected);
  EXPECT_EQ(report.strip_triangles, 4u);
  EXPECT_EQ(report.strip_degenerates, 4u);

  Bytes b;
  b.text("ply\nformat binary_little_endian 1.0\n").text(header);
  for (int v = 0; v < 10; ++v) b.put(float(v)).put(0.0f).put(0.0f);
  b.put(int32_t(13));
  for (int i : {0, 1, 2, 3, 3, 4, 4, 5, 6, -1, 7, 8, 9}) b.put(int32_t(i));
  EXPECT_EQ(read_text(b.str(), "strips.ply").faces, expected);
}

TEST(PlyReader, StripIndexOutOfRangeIsAnError) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement tristrips 1\nproperty list int int vertex_indices\n"
      "end_header\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2 -2\n";
  expect_error([&] { read_text(text, "s.ply"); }, ErrorCode::kInvalidInput,
               {"s.ply: line 13", "tristrips 0 has vertex index -2 but the file has 3 vertices"});
}

// ---- Malformed and hostile files. ----

TEST(PlyReader, TruncatedBinaryNamesTheByteOffset) {
  const std::string full = binary_ply(false);
  // Without the last byte (face 1's flags), the header's minimum sizes still hold: the
  // record reader finds the end.
  const std::string cut = full.substr(0, full.size() - 1);
  expect_error([&] { read_text(cut, "cut.ply"); }, ErrorCode::kInvalidInput,
               {"cut.ply: byte " + std::to_string(cut.size()) + ":", "ends inside face 1"});
  // Cut in the vertices: the header already declares more than the bytes left.
  const size_t header_end = full.find("end_header\n") + 11;
  expect_error([&] { read_text(full.substr(0, header_end + 20), "cut.ply"); },
               ErrorCode::kInvalidInput,
               {"cut.ply: line 4", "4 vertex elements", "20 bytes follow"});
}

TEST(PlyReader, AbsurdDeclaredCountsFailBeforeAllocating) {
  const std::string tail =
      "property float x\nproperty float y\nproperty float z\nend_header\n" + std::string(900, '\0');
  // 10^12 vertices: over the vertex limit.
  expect_error(
      [&] {
        read_text("ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n" + tail,
                  "huge.ply");
      },
      ErrorCode::kResourceExhausted, {"huge.ply", "1000000000000 vertices", "limit"});
  // 10^8 vertices: within the limit, but 1 kB cannot hold them.
  expect_error(
      [&] {
        read_text("ply\nformat binary_little_endian 1.0\nelement vertex 100000000\n" + tail,
                  "huge.ply");
      },
      ErrorCode::kInvalidInput, {"huge.ply: line 3", "100000000 vertex elements", "900 bytes"});
  // An unknown element counts too.
  expect_error(
      [&] {
        read_text(
            "ply\nformat ascii 1.0\nelement thing 18446744073709551615\n"
            "property uchar a\nend_header\n1 2 3\n",
            "huge.ply");
      },
      ErrorCode::kInvalidInput, {"huge.ply: line 3", "thing elements"});
  // A list declaring 4 billion indices in a few bytes.
  Bytes b;
  b.text("ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n")
      .text("property float y\nproperty float z\nelement face 1\n")
      .text("property list uint int vertex_indices\nend_header\n");
  const size_t at = b.size();
  b.put(uint32_t(4000000000u)).put(int32_t(0)).put(int32_t(1));
  expect_error([&] { read_text(b.str(), "list.ply"); }, ErrorCode::kInvalidInput,
               {"list.ply: byte " + std::to_string(at) + ":", "declares 4000000000 values"});
}

TEST(PlyReader, IndexOutOfRangeNamesThePositionAndTheIndex) {
  Bytes b;
  b.text("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n")
      .text("property float y\nproperty float z\nelement face 2\n")
      .text("property list uchar int vertex_indices\nend_header\n");
  for (int v = 0; v < 3; ++v) b.put(float(v)).put(0.0f).put(0.0f);
  b.put(uint8_t(3)).put(int32_t(0)).put(int32_t(1)).put(int32_t(2));
  b.put(uint8_t(3)).put(int32_t(0));
  const size_t at = b.size();
  b.put(int32_t(9999)).put(int32_t(2));
  expect_error([&] { read_text(b.str(), "bad.ply"); }, ErrorCode::kInvalidInput,
               {"bad.ply: byte " + std::to_string(at) +
                ": face 1 has vertex index 9999 but the file has 3 vertices"});

  const std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 -1 2\n";
  expect_error([&] { read_text(ascii, "bad.ply"); }, ErrorCode::kInvalidInput,
               {"bad.ply: line 14: face 1 has vertex index -1 but the file has 3 vertices"});
}

TEST(PlyReader, MalformedHeadersAndBodies) {
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  struct Case {
    std::string text;
    std::vector<std::string> parts;
  };
  const std::vector<Case> cases = {
      {"ply\nformat ascii 1.0\nelement vertex 0\n" + xyz, {"no end_header"}},
      {"ply\nformat binary_middle_endian 1.0\nend_header\n", {"line 2", "binary_middle_endian"}},
      {"ply\nelement vertex 0\n" + xyz + "end_header\n", {"no format line"}},
      {"ply\nformat ascii 1.0\nproperty float x\nend_header\n", {"line 3", "before any element"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
       {"line 4", "'quad'"}},
      {"ply\nformat ascii 1.0\nelement vertex lots\nend_header\n", {"line 3", "element"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
       "end_header\n0 0\n",
       {"line 3", "no scalar 'z'"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
           "element face 1\nproperty list float int vertex_indices\nend_header\n0 0 0\n3 0 0 0\n",
       {"line 8", "count type"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
           "element face 1\nproperty list uchar float vertex_indices\nend_header\n0 0 0\n3 0 0 0\n",
       {"line 7", "non-integer"}},
      {"ply\nformat ascii 1.0\nelement vertex 1\n" + xyz +
           "element face 1\nproperty uchar n\nend_header\n0 0 0\n3\n",
       {"line 7", "no vertex_indices"}},
      {"ply\nformat ascii 1.0\nelement vertex 2\n" + xyz + "end_header\n0 0 0\n0 zero 0\n",
       {"line 9", "vertex 1", "'zero'"}},
      {"ply\nformat ascii 1.0\nelement vertex 2\n" + xyz + "end_header\n0 0 0\n0.000000 0",
       {"line 9", "ends inside vertex 1"}},
      {"ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0\n0 0 0\n0 0 0\n2 0 1\n",
       {"line 13", "face 0 has 2 vertices"}},
      {"ply\nformat ascii 1.0\nelement vertex 3\n" + xyz +
           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0\n0 0 0\n0 0 0\n300 0 1\n",
       {"line 13", "300", "uchar"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    try {
      read_text(c.text, "m.ply");
      ADD_FAILURE() << "did not throw";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
      for (const std::string& part : c.parts)
        EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  }
}

TEST(PlyReader, GarbageAfterTheMagicIsAnError) {
  std::string garbage = "ply\n";
  for (int i = 0; i < 2000; ++i) garbage += char((i * 7919) % 256);
  expect_error([&] { read_text(garbage, "junk.ply"); }, ErrorCode::kInvalidInput, {"junk.ply"});
  expect_error([&] { read_text("not a ply file at all\n", "junk.ply"); }, ErrorCode::kInvalidInput,
               {"junk.ply", "not a PLY file"});
}

TEST(PlyReader, FaceLimitIsResourceExhausted) {
  ReadLimits limits;
  limits.max_faces = 2;
  expect_error([&] { read_text(binary_ply(false), "le.ply", nullptr, limits); },
               ErrorCode::kResourceExhausted, {"limit of 2 faces"});
}

}  // namespace
}  // namespace parapm
