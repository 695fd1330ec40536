// OBJ reader (Wavefront geometry, the subset that describes polygon meshes). Accepts:
//   v x y z [w]              w is ignored (noted in the report)
//   v x y z r g b [a]        vertex colours -> the colors channel (alpha 1 when absent)
//   vt u [v [w]]             texture coordinates (v = 0 when absent, w ignored)
//   vn x y z                 normals
//   f c1 c2 c3 [c4 ...]      corners a, a/b, a//c or a/b/c; negative indices are relative to
//                            the records read so far; polygons are fan-split:
//                            (a,b,c,d) -> (a,b,c), (a,c,d)
//   a '\' ending a line continues it on the next; '#' starts a comment
//   g o s usemtl mtllib      ignored, listed once each in ReadReport::ignored
//   other statements         ignored and listed when they look like a statement (a word of
//                            letters, digits, '_'): l, p, vp, curv, surf, ... of the spec
// Anything else (binary bytes, a word that is not a statement, a malformed number) is an error
// naming the line. Positive indices may refer forward (some writers put faces first); they are
// checked against the final counts. Wedges: see mesh_io.h (first-use order; corners without vt
// or vn in a file that has them get zeros in that channel).
#include <array>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/formats.h"
#include "io/text_scanner.h"
#include "io/wedge_table.h"

namespace parapm::io {
namespace {

enum RecordKind : uint8_t { kPosition, kTexcoord, kNormal };
const char* kind_name(RecordKind kind) {
  return kind == kPosition ? "vertex" : kind == kTexcoord ? "texture coordinate" : "normal";
}

struct Corner {
  uint32_t v, vt, vn;  // 0-based; vt / vn kNoId when absent
};

// A positive index beyond the records read so far: valid only if the file defines it later.
struct ForwardRef {
  uint64_t line;
  int64_t index;
  RecordKind kind;
};

constexpr std::array<float, 4> kWhite{1, 1, 1, 1};

// A trailing '\' (before blanks) continues the line.
bool continues(std::string_view line) {
  size_t n = line.size();
  while (n > 0 && is_blank(line[n - 1])) --n;
  return n > 0 && line[n - 1] == '\\';
}

std::string_view without_continuation(std::string_view line) {
  size_t n = line.size();
  while (n > 0 && is_blank(line[n - 1])) --n;
  return line.substr(0, n - 1);
}

// Statements of the OBJ specification that describe no polygon geometry (free-form curves
// and surfaces, points, lines, display and rendering attributes).
bool is_spec_statement(std::string_view word) {
  static constexpr std::string_view kStatements[] = {
      "vp",         "l",         "p",     "cstype",   "deg",      "bmat", "step",   "curv",
      "curv2",      "surf",      "parm",  "trim",     "hole",     "scrv", "sp",     "end",
      "con",        "mg",        "bevel", "c_interp", "d_interp", "lod",  "maplib", "usemap",
      "shadow_obj", "trace_obj", "ctech", "stech",    "call",     "csh"};
  for (std::string_view s : kStatements)
    if (word == s) return true;
  return false;
}

bool is_statement_word(std::string_view word) {
  if (word.empty() || word.size() > 32) return false;
  for (char c : word)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'))
      return false;
  return (word[0] >= 'a' && word[0] <= 'z') || (word[0] >= 'A' && word[0] <= 'Z');
}

class ObjParser {
 public:
  explicit ObjParser(const ReadContext& ctx) : ctx_(ctx) {}

  Mesh run() {
    const char* p = ctx_.bytes.data();
    const char* const end = p + ctx_.bytes.size();
    uint64_t line_no = 1;
    std::string joined;
    while (p < end) {
      const uint64_t first_line = line_no;
      std::string_view line = next_physical_line(p, end, line_no);
      if (!continues(line)) {
        parse_line(line, first_line);
        continue;
      }
      joined.clear();
      for (;;) {
        joined.append(without_continuation(line));
        joined += ' ';
        if (p >= end) break;
        line = next_physical_line(p, end, line_no);
        if (!continues(line)) {
          joined.append(line);
          break;
        }
      }
      parse_line(joined, first_line);
    }
    if (positions_.empty() && tri_corners_.empty() && !saw_statement_)
      fail(ctx_, "not an OBJ file: no 'v' or 'f' statement");
    check_forward_refs();
    return build();
  }

 private:
  static std::string_view next_physical_line(const char*& p, const char* end, uint64_t& line_no) {
    const char* nl = static_cast<const char*>(std::memchr(p, '\n', size_t(end - p)));
    const char* line_end = nl ? nl : end;
    std::string_view line(p, size_t(line_end - p));
    p = nl ? nl + 1 : end;
    ++line_no;
    return line;
  }

  void parse_line(std::string_view line, uint64_t line_no) {
    TextScanner s(line, line_no);
    s.skip_blanks();
    if (s.at_end() || s.peek() == '#') return;
    const std::string_view keyword = s.token();
    if (keyword == "v") return parse_vertex(s, line_no);
    if (keyword == "f") return parse_face(s, line_no);
    if (keyword == "vt") return parse_texcoord(s, line_no);
    if (keyword == "vn") return parse_normal(s, line_no);
    if (keyword == "g") return ignore("obj groups (g)");
    if (keyword == "o") return ignore("obj object names (o)");
    if (keyword == "s") return ignore("obj smoothing groups (s)");
    if (keyword == "usemtl") return ignore("obj materials (usemtl)");
    if (keyword == "mtllib") return ignore("obj material libraries (mtllib)");
    if (is_spec_statement(keyword)) return ignore("obj '" + std::string(keyword) + "' statements");
    if (!is_statement_word(keyword))
      fail_at_line(ctx_, line_no, "not an OBJ statement: " + quote(keyword));
    // A word we do not know: a vendor extension, or text that is not OBJ at all (then the
    // file has no geometry and fails at the end).
    note_ignored(ctx_, "obj unknown statements ('" + std::string(keyword) + "')");
  }

  void ignore(const std::string& what) {
    saw_statement_ = true;
    note_ignored(ctx_, what);
  }

  // Reads the next number of the line; `what` names it in the error.
  template <class T>
  T number(TextScanner& s, uint64_t line_no, const char* what) {
    s.skip_blanks();
    T value{};
    if (!s.read(value)) {
      const std::string_view found = s.token();
      fail_at_line(ctx_, line_no,
                   std::string("expected ") + what + ", found " +
                       (found.empty() ? std::string("the end of the line") : quote(found)));
    }
    return value;
  }

  // True when only blanks or a comment remain on the line.
  static bool line_done(TextScanner& s) {
    s.skip_blanks();
    return s.at_line_end() || s.peek() == '#';
  }

  void parse_vertex(TextScanner& s, uint64_t line_no) {
    if (positions_.size() >= ctx_.max_vertices())
      fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_vertices()) +
                           " vertices (line " + std::to_string(line_no) + ")");
    Vec3 p;
    p[0] = number<double>(s, line_no, "the x coordinate of a vertex");
    p[1] = number<double>(s, line_no, "the y coordinate of a vertex");
    p[2] = number<double>(s, line_no, "the z coordinate of a vertex");
    std::array<float, 4> extra{};
    int extras = 0;
    while (!line_done(s)) {
      if (extras == 4)
        fail_at_line(ctx_, line_no,
                     "a vertex has more than 7 values (x y z [w] or x y z r g b [a])");
      extra[extras] = number<float>(s, line_no, "a number");
      ++extras;
    }
    if (extras == 2)
      fail_at_line(ctx_, line_no, "a vertex has 5 values (x y z [w] or x y z r g b [a])");
    check_finite_position(ctx_, p, "vertex " + std::to_string(positions_.size() + 1), line_no);
    positions_.push_back(p);
    if (extras == 1) note_ignored(ctx_, "obj vertex w coordinates");
    if (extras >= 3) {
      if (colors_.empty()) {
        // The first coloured vertex: the ones before it have no colour.
        colors_.assign(positions_.size() - 1, kWhite);
        ctx_.report->vertices_without_color = positions_.size() - 1;
      }
      colors_.push_back({extra[0], extra[1], extra[2], extras == 4 ? extra[3] : 1.0f});
    } else if (!colors_.empty()) {
      colors_.push_back(kWhite);
      ++ctx_.report->vertices_without_color;
    }
  }

  void parse_texcoord(TextScanner& s, uint64_t line_no) {
    if (texcoords_.size() >= ctx_.max_vertices())
      fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_vertices()) +
                           " texture coordinates (line " + std::to_string(line_no) + ")");
    std::array<float, 2> t{};
    t[0] = number<float>(s, line_no, "the u texture coordinate");
    if (!line_done(s)) t[1] = number<float>(s, line_no, "the v texture coordinate");
    if (!line_done(s)) {
      number<float>(s, line_no, "the w texture coordinate");
      note_ignored(ctx_, "obj texture w coordinates");
    }
    if (!line_done(s)) fail_at_line(ctx_, line_no, "a texture coordinate has more than 3 values");
    texcoords_.push_back(t);
  }

  void parse_normal(TextScanner& s, uint64_t line_no) {
    if (normals_.size() >= ctx_.max_vertices())
      fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_vertices()) +
                           " normals (line " + std::to_string(line_no) + ")");
    std::array<float, 3> n;
    n[0] = number<float>(s, line_no, "the x of a normal");
    n[1] = number<float>(s, line_no, "the y of a normal");
    n[2] = number<float>(s, line_no, "the z of a normal");
    if (!line_done(s)) fail_at_line(ctx_, line_no, "a normal has more than 3 values");
    normals_.push_back(n);
  }

  // OBJ indices are 1-based, negative ones count back from the last record read.
  uint32_t resolve(int64_t index, RecordKind kind, uint64_t line_no) {
    const uint64_t count = kind == kPosition   ? positions_.size()
                           : kind == kTexcoord ? texcoords_.size()
                                               : normals_.size();
    if (index > 0) {
      const uint64_t i = uint64_t(index) - 1;
      if (i < count) return uint32_t(i);
      if (i >= ctx_.max_vertices())
        fail_at_line(ctx_, line_no,
                     std::string("face has ") + kind_name(kind) + " index " +
                         std::to_string(index) + ", beyond the limit of " +
                         std::to_string(ctx_.max_vertices()) + " records");
      forward_refs_.push_back({line_no, index, kind});
      return uint32_t(i);
    }
    if (index == 0)
      fail_at_line(
          ctx_, line_no,
          std::string("face has ") + kind_name(kind) + " index 0 (OBJ indices start at 1)");
    const uint64_t back = uint64_t(0) - uint64_t(index);
    if (back > count)
      fail_at_line(ctx_, line_no,
                   std::string("face has relative ") + kind_name(kind) + " index " +
                       std::to_string(index) + " but only " + std::to_string(count) + " " +
                       kind_name(kind) + " records precede it");
    return uint32_t(count - back);
  }

  void bad_corner(const char* start, const char* end, uint64_t line_no) {
    const char* e = start;
    while (e < end && !is_separator(*e)) ++e;
    fail_at_line(ctx_, line_no,
                 "bad face corner " + quote(std::string_view(start, size_t(e - start))) +
                     " (expected v, v/vt, v//vn or v/vt/vn)");
  }

  void parse_face(TextScanner& s, uint64_t line_no) {
    polygon_.clear();
    while (!line_done(s)) {
      const char* start = s.pos();
      int64_t index = 0;
      if (!s.read_until(index, '/')) bad_corner(start, s.end(), line_no);
      Corner c{resolve(index, kPosition, line_no), kNoId, kNoId};
      if (s.consume('/')) {
        if (s.peek() != '/') {
          if (!s.read_until(index, '/')) bad_corner(start, s.end(), line_no);
          c.vt = resolve(index, kTexcoord, line_no);
          has_texcoords_ = true;
        }
        if (s.consume('/')) {
          if (!s.read(index)) bad_corner(start, s.end(), line_no);
          c.vn = resolve(index, kNormal, line_no);
          has_normals_ = true;
        }
      }
      polygon_.push_back(c);
    }
    if (polygon_.size() < 3)
      fail_at_line(ctx_, line_no,
                   "a face has " + std::to_string(polygon_.size()) + " corners, at least 3 needed");
    ReadReport& report = *ctx_.report;
    ++report.polygons;
    if (polygon_.size() > 3) ++report.triangulated_polygons;
    const uint64_t triangles = tri_corners_.size() / 3 + polygon_.size() - 2;
    if (triangles > ctx_.max_faces())
      fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_faces()) +
                           " faces (line " + std::to_string(line_no) + ")");
    for (size_t i = 1; i + 1 < polygon_.size(); ++i) {
      tri_corners_.push_back(polygon_[0]);
      tri_corners_.push_back(polygon_[i]);
      tri_corners_.push_back(polygon_[i + 1]);
    }
  }

  void check_forward_refs() const {
    for (const ForwardRef& ref : forward_refs_) {
      const uint64_t count = ref.kind == kPosition   ? positions_.size()
                             : ref.kind == kTexcoord ? texcoords_.size()
                                                     : normals_.size();
      if (uint64_t(ref.index) > count)
        fail_at_line(ctx_, ref.line,
                     std::string("face has ") + kind_name(ref.kind) + " index " +
                         std::to_string(ref.index) + " but the file has " + std::to_string(count) +
                         " " + kind_name(ref.kind) + " records");
    }
  }

  Mesh build() {
    Mesh mesh;
    const size_t triangles = tri_corners_.size() / 3;
    mesh.faces.resize(triangles);
    for (size_t t = 0; t < triangles; ++t)
      for (int k = 0; k < 3; ++k) mesh.faces[t][k] = tri_corners_[3 * t + k].v;

    mesh.layout.normals = has_normals_;
    mesh.layout.texcoords = has_texcoords_;
    mesh.layout.colors = !colors_.empty();
    if (mesh.layout.any()) build_wedges(mesh);
    mesh.positions = std::move(positions_);
    finish_mesh(mesh);
    return mesh;
  }

  void build_wedges(Mesh& mesh) {
    ReadReport& report = *ctx_.report;
    WedgeTable table(tri_corners_.size());
    mesh.face_wedges.resize(mesh.faces.size());
    for (size_t t = 0; t < mesh.faces.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const Corner& c = tri_corners_[3 * t + k];
        // Channels the file lacks entirely are keyed as absent, so they do not split wedges.
        mesh.face_wedges[t][k] = table.find_or_add(c.v, c.vt, c.vn);
        if (table.size() > ctx_.max_vertices())
          fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_vertices()) +
                               " wedges (distinct v/vt/vn corners)");
        if (has_texcoords_ && c.vt == kNoId) ++report.corners_without_texcoord;
        if (has_normals_ && c.vn == kNoId) ++report.corners_without_normal;
      }
    }
    const AttributeLayout& layout = mesh.layout;
    const size_t stride = size_t(layout.floats_per_wedge());
    mesh.wedge_values.assign(table.size() * stride, 0.0f);
    for (WedgeId w = 0; w < table.size(); ++w) {
      float* out = mesh.wedge_values.data() + size_t(w) * stride;
      if (layout.normals && table.normal(w) != kNoId) {
        const auto& n = normals_[table.normal(w)];
        std::copy(n.begin(), n.end(), out + layout.normal_offset());
      }
      if (layout.texcoords && table.texcoord(w) != kNoId) {
        const auto& uv = texcoords_[table.texcoord(w)];
        std::copy(uv.begin(), uv.end(), out + layout.texcoord_offset());
      }
      if (layout.colors) {
        const auto& rgba = colors_[table.vertices()[w]];
        std::copy(rgba.begin(), rgba.end(), out + layout.color_offset());
      }
    }
    mesh.wedge_vertex = std::move(table.vertices());
  }

  const ReadContext& ctx_;
  std::vector<Vec3> positions_;
  std::vector<std::array<float, 4>> colors_;  // empty, or one per position
  std::vector<std::array<float, 2>> texcoords_;
  std::vector<std::array<float, 3>> normals_;
  std::vector<Corner> tri_corners_;  // 3 per triangle
  std::vector<Corner> polygon_;      // scratch for the face being read
  std::vector<ForwardRef> forward_refs_;
  bool has_texcoords_ = false;
  bool has_normals_ = false;
  bool saw_statement_ = false;  // a known non-geometry statement: OBJ, maybe without geometry
};

}  // namespace

Mesh read_obj(const ReadContext& ctx) {
  ctx.report->format = MeshFormat::kObj;
  ctx.report->encoding = "ascii";
  return ObjParser(ctx).run();
}

}  // namespace parapm::io
