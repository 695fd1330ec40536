// STL reader. Accepts:
//   binary  an 80-byte header, a little-endian uint32 triangle count, then 50 bytes per
//           triangle (normal, 3 corners as float32, a 2-byte attribute); the file size must
//           be exactly 84 + 50 * count;
//   ascii   "solid [name]", then facets "facet normal nx ny nz / outer loop / vertex x y z
//           (3 or more) / endloop / endfacet", then "endsolid [name]"; several solids follow
//           one another; keywords in any case; facets with more than 3 vertices are fan-split.
// A file that starts with "solid" is binary when its size matches its count exactly (some
// binary writers start the header with "solid"), ascii otherwise.
//
// STL stores every triangle with its own corners: corners with exactly equal coordinates are
// welded into one vertex (hashing the bit patterns; -0 and +0 are the same coordinate), first
// occurrence first, and ReadReport::welded_vertices counts the corners merged. Facet normals
// and attribute bytes are ignored (listed). Coordinates of ascii files are read as double.
#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include "io/formats.h"
#include "io/place_table.h"
#include "io/text_scanner.h"

namespace parapm::io {
namespace {

constexpr uint64_t kBinaryHeaderBytes = 84;
constexpr uint64_t kBinaryTriangleBytes = 50;

uint32_t binary_count(std::string_view bytes) {
  uint32_t count;
  std::memcpy(&count, bytes.data() + 80, 4);
  if constexpr (std::endian::native == std::endian::big) count = __builtin_bswap32(count);
  return count;
}

// Merges corners with bit-identical coordinates into one vertex (place_table.h), first
// occurrence first.
class Welder {
 public:
  Welder(Mesh& mesh, uint64_t max_corners) : mesh_(mesh), places_(mesh.positions, max_corners) {}

  VertexId vertex(const Vec3& p) {
    ++corners_;
    const auto v = VertexId(mesh_.positions.size());
    mesh_.positions.push_back(p);
    const VertexId first = places_.first_at(v);
    if (first != v) mesh_.positions.pop_back();
    return first;
  }

  uint64_t corners() const { return corners_; }

 private:
  Mesh& mesh_;
  PlaceTable places_;
  uint64_t corners_ = 0;
};

bool starts_with_solid(std::string_view bytes) {
  size_t i = 0;
  while (i < bytes.size() && is_separator(bytes[i])) ++i;
  return bytes.size() - i >= 5 && equals_ignore_case(bytes.substr(i, 5), "solid");
}

// Binary data in the first bytes (NUL or other control bytes): not an ascii STL.
bool looks_binary(std::string_view bytes) {
  const size_t n = std::min<size_t>(bytes.size(), 512);
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(bytes[i]);
    if (c < 0x20 && !is_separator(char(c))) return true;
  }
  return false;
}

std::string size_mismatch(std::string_view bytes) {
  const uint64_t count = binary_count(bytes);
  return "as binary STL it declares " + std::to_string(count) + " triangles, which take " +
         std::to_string(kBinaryHeaderBytes + kBinaryTriangleBytes * count) +
         " bytes (84 + 50 per triangle), but the file has " + std::to_string(bytes.size()) +
         " bytes";
}

Mesh read_binary(const ReadContext& ctx) {
  const std::string_view bytes = ctx.bytes;
  const uint64_t count = binary_count(bytes);
  check_face_limit(ctx, count, "the binary STL declares " + std::to_string(count) + " triangles");
  if (!stl_binary_size_matches(bytes)) fail(ctx, size_mismatch(bytes));
  Mesh mesh;
  mesh.faces.reserve(size_t(count));
  Welder welder(mesh, count * 3);
  bool attributes = false;
  const char* record = bytes.data() + kBinaryHeaderBytes;
  for (uint64_t f = 0; f < count; ++f, record += kBinaryTriangleBytes) {
    Triangle t;
    for (int c = 0; c < 3; ++c) {
      uint32_t bits[3];
      std::memcpy(bits, record + 12 + 12 * c, 12);
      Vec3 p;
      for (int k = 0; k < 3; ++k) {
        if constexpr (std::endian::native == std::endian::big) bits[k] = __builtin_bswap32(bits[k]);
        p[k] = double(std::bit_cast<float>(bits[k]));
      }
      check_finite_position(ctx, p, "triangle " + std::to_string(f) + " (from 0)", 0);
      t[c] = welder.vertex(p);
    }
    mesh.faces.push_back(t);
    attributes |= record[48] != 0 || record[49] != 0;
  }
  if (mesh.positions.size() > ctx.max_vertices())
    fail_limit(ctx, "more than the limit of " + std::to_string(ctx.max_vertices()) + " vertices");
  if (count > 0) note_ignored(ctx, "stl facet normals");
  if (attributes) note_ignored(ctx, "stl facet attribute bytes (colours)");
  ctx.report->polygons = count;
  ctx.report->welded_vertices = welder.corners() - mesh.positions.size();
  return mesh;
}

class AsciiStlParser {
 public:
  explicit AsciiStlParser(const ReadContext& ctx) : ctx_(ctx), s_(ctx.bytes) {}

  Mesh run() {
    // A rough bound for the welder's first table: a facet takes well over 100 bytes.
    Welder welder(mesh_, std::min<uint64_t>(ctx_.bytes.size() / 40 + 16, uint64_t(1) << 24));
    welder_ = &welder;
    expect("solid");
    for (;;) {
      s_.next_line();  // the rest of the "solid" line is the name
      read_facets();   // up to "endsolid"
      s_.next_line();  // its name
      s_.skip_space();
      if (s_.at_end()) break;
      expect("solid");
    }
    if (!mesh_.faces.empty()) note_ignored(ctx_, "stl facet normals");
    ctx_.report->welded_vertices = welder.corners() - mesh_.positions.size();
    return std::move(mesh_);
  }

 private:
  [[noreturn]] void unexpected(std::string_view found, const std::string& expected) {
    if (found.empty() && s_.at_end())
      fail_at_line(ctx_, s_.line(), "the file ends where " + expected + " was expected");
    fail_at_line(ctx_, s_.line(), "expected " + expected + ", found " + quote(found));
  }

  void expect(std::string_view keyword) {
    const std::string_view t = s_.next_token();
    if (equals_ignore_case(t, keyword)) return;
    std::string expected = "'";
    expected.append(keyword);
    expected += '\'';
    unexpected(t, expected);
  }

  double number(const char* what) {
    s_.skip_space();
    double v;
    if (!s_.read(v)) unexpected(s_.token(), what);
    return v;
  }

  void read_facets() {
    ReadReport& report = *ctx_.report;
    for (;;) {
      const std::string_view t = s_.next_token();
      if (equals_ignore_case(t, "endsolid")) return;
      if (!equals_ignore_case(t, "facet")) unexpected(t, "'facet' or 'endsolid'");
      const uint64_t line = s_.line();
      expect("normal");
      for (int k = 0; k < 3; ++k) number("a facet normal component");
      expect("outer");
      expect("loop");
      polygon_.clear();
      for (;;) {
        const std::string_view v = s_.next_token();
        if (equals_ignore_case(v, "endloop")) break;
        if (!equals_ignore_case(v, "vertex")) unexpected(v, "'vertex' or 'endloop'");
        Vec3 p;
        p[0] = number("the x coordinate of a vertex");
        p[1] = number("the y coordinate of a vertex");
        p[2] = number("the z coordinate of a vertex");
        check_finite_position(ctx_, p, "a vertex", s_.line());
        polygon_.push_back(welder_->vertex(p));
      }
      expect("endfacet");
      if (polygon_.size() < 3)
        fail_at_line(
            ctx_, line,
            "a facet has " + std::to_string(polygon_.size()) + " vertices, at least 3 needed");
      if (mesh_.faces.size() + polygon_.size() - 2 > ctx_.max_faces())
        fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_faces()) +
                             " faces (line " + std::to_string(line) + ")");
      for (size_t j = 1; j + 1 < polygon_.size(); ++j)
        mesh_.faces.push_back({polygon_[0], polygon_[j], polygon_[j + 1]});
      ++report.polygons;
      if (polygon_.size() > 3) ++report.triangulated_polygons;
      if (mesh_.positions.size() > ctx_.max_vertices())
        fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_vertices()) +
                             " vertices (line " + std::to_string(line) + ")");
    }
  }

  const ReadContext& ctx_;
  TextScanner s_;
  Mesh mesh_;
  Welder* welder_ = nullptr;
  std::vector<VertexId> polygon_;
};

}  // namespace

bool stl_binary_size_matches(std::string_view bytes) {
  return bytes.size() >= kBinaryHeaderBytes &&
         kBinaryHeaderBytes + kBinaryTriangleBytes * uint64_t(binary_count(bytes)) == bytes.size();
}

bool stl_start_fits(std::string_view start) {
  if (starts_with_solid(start)) return true;
  return start.size() < kBinaryHeaderBytes ||
         kBinaryHeaderBytes + kBinaryTriangleBytes * uint64_t(binary_count(start)) >= start.size();
}

Mesh read_stl(const ReadContext& ctx) {
  ReadReport& report = *ctx.report;
  report.format = MeshFormat::kStl;
  Mesh mesh;
  if (stl_binary_size_matches(ctx.bytes) || !starts_with_solid(ctx.bytes)) {
    if (ctx.bytes.size() < kBinaryHeaderBytes)
      fail(ctx, "too short for a binary STL (" + std::to_string(ctx.bytes.size()) +
                    " bytes, the header alone takes 84) and it does not start with 'solid'");
    report.encoding = "binary";
    mesh = read_binary(ctx);
  } else {
    if (looks_binary(ctx.bytes) && ctx.bytes.size() >= kBinaryHeaderBytes)
      fail(ctx, "starts with 'solid' but holds binary data, and " + size_mismatch(ctx.bytes));
    report.encoding = "ascii";
    mesh = AsciiStlParser(ctx).run();
  }
  finish_mesh(mesh);
  return mesh;
}

}  // namespace parapm::io
