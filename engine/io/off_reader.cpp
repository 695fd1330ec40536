// OFF reader (Geomview Object File Format, text). Accepts:
//   a header keyword [ST][C][N]OFF: OFF, COFF, NOFF, CNOFF, STOFF, STCNOFF, ...; the extra
//     per-vertex values these announce (texture coordinates, colours, normals) are skipped and
//     listed in ReadReport::ignored;
//   the counts "vertices faces [edges]", on the header line or the next line;
//   one vertex per line, "x y z [extra values]";
//   one face per line, "n i1 ... in [colour values]", 0-based indices; polygons fan-split and
//     colour values skipped (listed);
//   '#' comments, whole lines or after the values; blank lines; "\r\n" line ends.
// Refused: 4OFF and nOFF (not 3D) and binary OFF. Errors name the line.
#include <string>
#include <vector>

#include "io/formats.h"
#include "io/text_scanner.h"

namespace parapm::io {
namespace {

struct OffKeyword {
  bool texcoords = false, colors = false, normals = false, four_d = false, n_d = false;
};

bool parse_off_keyword(std::string_view token, OffKeyword* out) {
  OffKeyword k;
  auto take = [&](std::string_view prefix) {
    if (token.substr(0, prefix.size()) != prefix) return false;
    token.remove_prefix(prefix.size());
    return true;
  };
  k.texcoords = take("ST");
  k.colors = take("C");
  k.normals = take("N");
  k.four_d = take("4");
  k.n_d = take("n");
  if (token != "OFF") return false;
  if (out) *out = k;
  return true;
}

class OffParser {
 public:
  explicit OffParser(const ReadContext& ctx) : ctx_(ctx), s_(ctx.bytes) {}

  Mesh run() {
    if (!next_data_line()) fail(ctx_, "not an OFF file: it has no header");
    const uint64_t header_line = s_.line();
    const std::string_view keyword = s_.token();
    OffKeyword k;
    if (!parse_off_keyword(keyword, &k))
      fail_at_line(ctx_, header_line, "not an OFF file: the header is " + quote(keyword));
    if (k.four_d || k.n_d)
      fail_at_line(ctx_, header_line, "only 3D OFF is supported, not " + quote(keyword));
    if (k.texcoords) note_ignored(ctx_, "off vertex texture coordinates");
    if (k.colors) note_ignored(ctx_, "off vertex colours");
    if (k.normals) note_ignored(ctx_, "off vertex normals");
    s_.skip_blanks();
    if (!at_line_end_or_comment()) {
      const std::string_view word = s_.token();
      if (word == "BINARY") fail_at_line(ctx_, header_line, "binary OFF is not supported");
      s_ = TextScanner(word.data(), s_.end(), header_line);  // the counts follow the keyword
    } else if (!next_data_line()) {
      fail(ctx_, "the file ends before the OFF counts line");
    }
    read_counts();
    read_vertices();
    read_faces();
    if (next_data_line()) note_ignored(ctx_, "off data after the last face");
    finish_mesh(mesh_);
    return std::move(mesh_);
  }

 private:
  bool at_line_end_or_comment() const { return s_.at_line_end() || s_.peek() == '#'; }

  // Moves to the first value of the next line holding data; false at the end of the file.
  bool next_data_line() {
    for (;;) {
      s_.skip_space();
      if (s_.at_end()) return false;
      if (s_.peek() != '#') return true;
      s_.next_line();
    }
  }

  template <class T>
  T number(const char* what) {
    s_.skip_blanks();
    T value{};
    if (!s_.read(value)) {
      const std::string_view found = at_line_end_or_comment() ? std::string_view() : s_.token();
      fail_at_line(ctx_, s_.line(),
                   std::string("expected ") + what + ", found " +
                       (found.empty() ? std::string("the end of the line") : quote(found)));
    }
    return value;
  }

  void read_counts() {
    vertex_count_ = number<uint64_t>("the vertex count");
    face_count_ = number<uint64_t>("the face count");
    s_.skip_blanks();
    if (!at_line_end_or_comment()) number<uint64_t>("the edge count");
    check_vertex_limit(ctx_, vertex_count_,
                       "the header declares " + std::to_string(vertex_count_) + " vertices");
    check_face_limit(ctx_, face_count_,
                     "the header declares " + std::to_string(face_count_) + " faces");
    // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line 8 ("3 0 1 2\n").
    const uint64_t available = s_.remaining() + 1;
    if (vertex_count_ > available / 6 || face_count_ > (available - vertex_count_ * 6) / 8)
      fail_at_line(ctx_, s_.line(),
                   "the header declares " + std::to_string(vertex_count_) + " vertices and " +
                       std::to_string(face_count_) + " faces but only " +
                       std::to_string(s_.remaining()) + " bytes follow");
    s_.next_line();
  }

  void read_vertices() {
    mesh_.positions.reserve(size_t(vertex_count_));
    for (uint64_t i = 0; i < vertex_count_; ++i) {
      if (!next_data_line())
        fail_at_line(ctx_, s_.line(),
                     "the file ends after " + std::to_string(i) + " of " +
                         std::to_string(vertex_count_) + " vertices");
      Vec3 p;
      p[0] = number<double>("the x coordinate of a vertex");
      p[1] = number<double>("the y coordinate of a vertex");
      p[2] = number<double>("the z coordinate of a vertex");
      check_finite_position(ctx_, p, "vertex " + std::to_string(i), s_.line());
      mesh_.positions.push_back(p);
      s_.skip_blanks();
      if (!at_line_end_or_comment()) note_ignored(ctx_, "off extra vertex values");
      s_.next_line();
    }
  }

  void read_faces() {
    mesh_.faces.reserve(size_t(face_count_));
    ReadReport& report = *ctx_.report;
    for (uint64_t i = 0; i < face_count_; ++i) {
      if (!next_data_line())
        fail_at_line(ctx_, s_.line(),
                     "the file ends after " + std::to_string(i) + " of " +
                         std::to_string(face_count_) + " faces");
      const uint64_t line = s_.line();
      const uint64_t n = number<uint64_t>("the corner count of a face");
      if (n < 3)
        fail_at_line(ctx_, line,
                     "face " + std::to_string(i) + " has " + std::to_string(n) +
                         " vertices, at least 3 needed");
      polygon_.clear();
      for (uint64_t j = 0; j < n; ++j) {
        s_.skip_blanks();
        if (at_line_end_or_comment())
          fail_at_line(ctx_, line,
                       "face " + std::to_string(i) + " declares " + std::to_string(n) +
                           " vertices but the line has " + std::to_string(j));
        const int64_t index = number<int64_t>("a vertex index");
        if (index < 0 || uint64_t(index) >= vertex_count_)
          fail_at_line(ctx_, line,
                       "face " + std::to_string(i) + " has vertex index " + std::to_string(index) +
                           " but the file has " + std::to_string(vertex_count_) + " vertices");
        polygon_.push_back(VertexId(index));
      }
      if (mesh_.faces.size() + n - 2 > ctx_.max_faces())
        fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_faces()) +
                             " faces (line " + std::to_string(line) + ")");
      for (size_t j = 1; j + 1 < polygon_.size(); ++j)
        mesh_.faces.push_back({polygon_[0], polygon_[j], polygon_[j + 1]});
      ++report.polygons;
      if (n > 3) ++report.triangulated_polygons;
      s_.skip_blanks();
      if (!at_line_end_or_comment()) note_ignored(ctx_, "off face colours");
      s_.next_line();
    }
  }

  const ReadContext& ctx_;
  TextScanner s_;
  uint64_t vertex_count_ = 0;
  uint64_t face_count_ = 0;
  std::vector<VertexId> polygon_;
  Mesh mesh_;
};

}  // namespace

bool is_off_keyword(std::string_view token) { return parse_off_keyword(token, nullptr); }

Mesh read_off(const ReadContext& ctx) {
  ctx.report->format = MeshFormat::kOff;
  ctx.report->encoding = "ascii";
  return OffParser(ctx).run();
}

}  // namespace parapm::io
