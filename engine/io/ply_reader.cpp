// PLY reader. Accepts ascii, binary_little_endian and binary_big_endian files with any
// property types (see ply_format.h), and from them:
//   element vertex      x y z (any numeric type) -> positions;
//                       nx ny nz -> normals; red green blue [alpha] -> colours (uchar / 255,
//                       ushort / 65535, float and double as they are); s t, u v, texture_u
//                       texture_v or texture_s texture_t -> texcoords. Other vertex
//                       properties are skipped and listed in ReadReport::ignored.
//   element face        list vertex_indices (or vertex_index), any count and index types;
//                       polygons are fan-split; other face properties skipped and listed.
//   element tristrips   list vertex_indices: -1 ends a strip; inside a strip, triangle j is
//                       (s[j], s[j+1], s[j+2]) for even j and (s[j+1], s[j], s[j+2]) for odd j
//                       (orientation alternates); triangles with a repeated index (the
//                       degenerate joints) are not faces (counted in strip_degenerates).
//   other elements      skipped (lists included) and listed.
// Attributes are per vertex: wedge i is vertex i, face_wedges == faces.
//
// Untrusted input: the header's counts are checked against the limits (kResourceExhausted)
// and then against the bytes after the header (each record needs a minimum number of bytes)
// before anything is allocated; each list length is checked against the bytes left before it
// is read; each index against the declared vertex count. Errors name the line (ascii) or the
// byte offset (binary).
#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include "io/formats.h"
#include "io/ply_format.h"
#include "io/text_scanner.h"
#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm::io {
namespace {

std::string record_name(const PlyElement& e, uint64_t index) {
  return e.name + " " + std::to_string(index);
}

// ---- Value sources: the same element readers run over ascii text and binary data. ----

class AsciiSource {
 public:
  AsciiSource(const ReadContext& ctx, const PlyHeader& header)
      : ctx_(ctx),
        s_(ctx.bytes.data() + header.body_offset, ctx.bytes.data() + ctx.bytes.size(),
           header.body_line) {}
  // The text [begin, end) of the body, starting on line `first_line`: a chunk of lines.
  AsciiSource(const ReadContext& ctx, const char* begin, const char* end, uint64_t first_line)
      : ctx_(ctx), s_(begin, end, first_line) {}

  void begin_record(const PlyElement& e, uint64_t index) {
    element_ = &e;
    index_ = index;
  }

  double scalar(PlyType type) {
    s_.skip_space();
    if (type == PlyType::kFloat32) {
      float f;
      if (!s_.read(f)) bad_value();
      return f;
    }
    if (type == PlyType::kFloat64) {
      double d;
      if (!s_.read(d)) bad_value();
      return d;
    }
    return double(integer(type));
  }

  int64_t integer(PlyType type) {
    s_.skip_space();
    int64_t v;
    if (!s_.read(v)) bad_value();
    if (!fits(type, v))
      fail_here(record_name(*element_, index_) + ": value " + std::to_string(v) +
                " does not fit its type " + ply_type_name(type));
    return v;
  }

  void skip(PlyType) {
    s_.skip_space();
    if (s_.token().empty()) bad_value();
  }

  uint64_t list_count(const PlyProperty& p) {
    const int64_t n = integer(p.count_type);
    if (n < 0)
      fail_here(record_name(*element_, index_) + ": list '" + p.name + "' has negative length " +
                std::to_string(n));
    // Each item needs a separator and a digit.
    if (uint64_t(n) > (s_.remaining() + 1) / 2)
      fail_here(record_name(*element_, index_) + ": list '" + p.name + "' declares " +
                std::to_string(n) + " values but only " + std::to_string(s_.remaining()) +
                " bytes remain");
    return uint64_t(n);
  }

  // Ascii positions are lines; mark() is where the next value starts.
  uint64_t mark() {
    s_.skip_space();
    return s_.line();
  }
  [[noreturn]] void fail_at(uint64_t line, const std::string& what) {
    fail_at_line(ctx_, line, what);
  }
  [[noreturn]] void fail_here(const std::string& what) { fail_at_line(ctx_, s_.line(), what); }

  // Skips `count` records of a list-free element.
  void skip_records(const PlyElement& e, uint64_t count) {
    for (uint64_t i = 0; i < count; ++i) {
      begin_record(e, i);
      for (const PlyProperty& p : e.properties) skip(p.type);
    }
  }

  void finish() {
    s_.skip_space();
    if (!s_.at_end())
      note_ignored(ctx_,
                   "ply data after the last element (line " + std::to_string(s_.line()) + ")");
  }

  uint64_t remaining() const { return s_.remaining(); }

 private:
  static bool fits(PlyType type, int64_t v) {
    switch (type) {
      case PlyType::kInt8:
        return v >= -128 && v <= 127;
      case PlyType::kUint8:
        return v >= 0 && v <= 255;
      case PlyType::kInt16:
        return v >= -32768 && v <= 32767;
      case PlyType::kUint16:
        return v >= 0 && v <= 65535;
      case PlyType::kInt32:
        return v >= INT32_MIN && v <= INT32_MAX;
      case PlyType::kUint32:
        return v >= 0 && v <= int64_t(UINT32_MAX);
      default:
        return true;
    }
  }

  [[noreturn]] void bad_value() {
    s_.skip_space();
    if (s_.at_end())
      fail_here("the file ends inside " + record_name(*element_, index_) +
                " (the header declares " + std::to_string(element_->count) + ")");
    const std::string_view found = s_.token();
    fail_here(record_name(*element_, index_) + ": expected a number, found " + quote(found));
  }

  const ReadContext& ctx_;
  TextScanner s_;
  const PlyElement* element_ = nullptr;
  uint64_t index_ = 0;
};

template <bool kSwap>
class BinarySource {
 public:
  BinarySource(const ReadContext& ctx, const PlyHeader& header)
      : ctx_(ctx),
        base_(ctx.bytes.data()),
        p_(base_ + header.body_offset),
        end_(base_ + ctx.bytes.size()) {}
  // The bytes [begin, end) of ctx.bytes (a chunk of records; offsets in messages stay the file's).
  BinarySource(const ReadContext& ctx, const char* begin, const char* end)
      : ctx_(ctx), base_(ctx.bytes.data()), p_(begin), end_(end) {}

  void begin_record(const PlyElement& e, uint64_t index) {
    element_ = &e;
    index_ = index;
  }

  double scalar(PlyType type) {
    need(ply_type_size(type));
    switch (type) {
      case PlyType::kInt8:
        return double(int8_t(load<uint8_t>()));
      case PlyType::kUint8:
        return double(load<uint8_t>());
      case PlyType::kInt16:
        return double(int16_t(load<uint16_t>()));
      case PlyType::kUint16:
        return double(load<uint16_t>());
      case PlyType::kInt32:
        return double(int32_t(load<uint32_t>()));
      case PlyType::kUint32:
        return double(load<uint32_t>());
      case PlyType::kFloat32:
        return double(std::bit_cast<float>(load<uint32_t>()));
      case PlyType::kFloat64:
        return std::bit_cast<double>(load<uint64_t>());
    }
    return 0;
  }

  // Only called for integer types (list counts and indices; the header checks them).
  int64_t integer(PlyType type) {
    need(ply_type_size(type));
    switch (type) {
      case PlyType::kInt8:
        return int8_t(load<uint8_t>());
      case PlyType::kUint8:
        return load<uint8_t>();
      case PlyType::kInt16:
        return int16_t(load<uint16_t>());
      case PlyType::kUint16:
        return load<uint16_t>();
      case PlyType::kInt32:
        return int32_t(load<uint32_t>());
      case PlyType::kUint32:
        return load<uint32_t>();
      default:
        fail_here("internal: integer read of a float property");
    }
  }

  void skip(PlyType type) {
    need(ply_type_size(type));
    p_ += ply_type_size(type);
  }

  uint64_t list_count(const PlyProperty& p) {
    const uint64_t at = offset();
    const int64_t n = integer(p.count_type);
    if (n < 0)
      fail_at(at, record_name(*element_, index_) + ": list '" + p.name + "' has negative length " +
                      std::to_string(n));
    if (uint64_t(n) > remaining() / uint64_t(ply_type_size(p.type)))
      fail_at(at, record_name(*element_, index_) + ": list '" + p.name + "' declares " +
                      std::to_string(n) + " values of " + std::to_string(ply_type_size(p.type)) +
                      " bytes but only " + std::to_string(remaining()) + " bytes remain");
    return uint64_t(n);
  }

  uint64_t mark() const { return offset(); }
  [[noreturn]] void fail_at(uint64_t byte, const std::string& what) {
    fail_at_byte(ctx_, byte, what);
  }
  [[noreturn]] void fail_here(const std::string& what) { fail_at_byte(ctx_, offset(), what); }

  void skip_records(const PlyElement& e, uint64_t count) {
    const uint64_t size = e.fixed_record_bytes();
    if (size != 0 && count > remaining() / size) {
      begin_record(e, remaining() / size);
      p_ += remaining() / size * size;
      truncated();
    }
    p_ += size * count;
  }

  void finish() {
    if (p_ != end_)
      note_ignored(ctx_,
                   "ply data after the last element (" + std::to_string(end_ - p_) + " bytes)");
  }

  uint64_t remaining() const { return uint64_t(end_ - p_); }

 private:
  uint64_t offset() const { return uint64_t(p_ - base_); }

  void need(int bytes) {
    if (end_ - p_ < bytes) truncated();
  }
  [[noreturn]] void truncated() {
    fail_here("the file ends inside " + record_name(*element_, index_) + " (the header declares " +
              std::to_string(element_->count) + ")");
  }

  template <class U>
  U load() {
    U v;
    std::memcpy(&v, p_, sizeof v);
    p_ += sizeof v;
    if constexpr (kSwap && sizeof(U) == 2) v = U(__builtin_bswap16(v));
    if constexpr (kSwap && sizeof(U) == 4) v = U(__builtin_bswap32(v));
    if constexpr (kSwap && sizeof(U) == 8) v = U(__builtin_bswap64(v));
    return v;
  }

  const ReadContext& ctx_;
  const char* base_;
  const char* p_;
  const char* end_;
  const PlyElement* element_ = nullptr;
  uint64_t index_ = 0;
};

// ---- What each vertex property is for. ----

enum VertexSlot : int { kX, kY, kZ, kNx, kNy, kNz, kS, kT, kRed, kGreen, kBlue, kAlpha, kSlots };
constexpr int kSkip = -1;

struct VertexPlan {
  std::vector<int> slot;        // per property: a VertexSlot or kSkip
  std::vector<double> divisor;  // per property: colour normalisation (255 for uchar), else 1
  AttributeLayout layout;
};

int find_property(const PlyElement& e, std::string_view name) {
  for (size_t i = 0; i < e.properties.size(); ++i)
    if (e.properties[i].name == name && !e.properties[i].is_list) return int(i);
  return -1;
}

VertexPlan plan_vertices(const ReadContext& ctx, const PlyElement& e) {
  VertexPlan plan;
  plan.slot.assign(e.properties.size(), kSkip);
  plan.divisor.assign(e.properties.size(), 1.0);
  auto assign = [&](std::initializer_list<std::pair<std::string_view, int>> group) {
    std::vector<int> found;
    for (const auto& [name, slot] : group) {
      const int i = find_property(e, name);
      if (i < 0 || plan.slot[size_t(i)] != kSkip) return false;
      found.push_back(i);
    }
    size_t k = 0;
    for (const auto& entry : group) plan.slot[size_t(found[k++])] = entry.second;
    return true;
  };
  for (const char* axis : {"x", "y", "z"})
    if (find_property(e, axis) < 0)
      fail_at_line(ctx, e.line,
                   std::string("the vertex element has no scalar '") + axis + "' property");
  assign({{"x", kX}, {"y", kY}, {"z", kZ}});
  plan.layout.normals = assign({{"nx", kNx}, {"ny", kNy}, {"nz", kNz}});
  plan.layout.texcoords = assign({{"s", kS}, {"t", kT}}) || assign({{"u", kS}, {"v", kT}}) ||
                          assign({{"texture_u", kS}, {"texture_v", kT}}) ||
                          assign({{"texture_s", kS}, {"texture_t", kT}});
  // Colours: integer channels are normalised by their type's maximum.
  auto color_divisor = [](PlyType t) {
    switch (t) {
      case PlyType::kUint8:
        return 255.0;
      case PlyType::kUint16:
        return 65535.0;
      case PlyType::kFloat32:
      case PlyType::kFloat64:
        return 1.0;
      default:
        return 0.0;  // signed or 32-bit integer colours: meaning unclear
    }
  };
  const int r = find_property(e, "red"), g = find_property(e, "green"),
            b = find_property(e, "blue"), a = find_property(e, "alpha");
  if (r >= 0 && g >= 0 && b >= 0) {
    bool usable = true;
    for (int i : {r, g, b, a})
      if (i >= 0 && color_divisor(e.properties[size_t(i)].type) == 0.0) usable = false;
    if (usable) {
      plan.layout.colors = true;
      const std::pair<int, int> channels[] = {{r, kRed}, {g, kGreen}, {b, kBlue}, {a, kAlpha}};
      for (const auto& [i, slot] : channels) {
        if (i < 0) continue;
        plan.slot[size_t(i)] = slot;
        plan.divisor[size_t(i)] = color_divisor(e.properties[size_t(i)].type);
      }
    }
  }
  for (size_t i = 0; i < e.properties.size(); ++i)
    if (plan.slot[i] == kSkip)
      note_ignored(ctx, "ply vertex property '" + e.properties[i].name + "'");
  return plan;
}

// Finds the list of vertex indices of a face or tristrips element.
int index_list(const ReadContext& ctx, const PlyElement& e) {
  int found = -1;
  for (size_t i = 0; i < e.properties.size(); ++i) {
    const PlyProperty& p = e.properties[i];
    if (found < 0 && p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index")) {
      if (!ply_type_is_integer(p.type))
        fail_at_line(ctx, e.line,
                     "the " + e.name + " element's '" + p.name + "' list has non-integer type " +
                         ply_type_name(p.type));
      found = int(i);
    } else {
      note_ignored(ctx, "ply " + e.name + " property '" + p.name + "'");
    }
  }
  if (found < 0) fail_at_line(ctx, e.line, "the " + e.name + " element has no vertex_indices list");
  return found;
}

// ---- The body. ----

template <class Source>
class PlyBody {
 public:
  PlyBody(const ReadContext& ctx, const PlyHeader& header, Source& src, uint64_t vertex_count)
      : ctx_(ctx), header_(header), src_(src), vertex_count_(vertex_count) {}

  Mesh read() {
    bool have_vertices = false;
    for (const PlyElement& e : header_.elements) {
      if (e.name == "vertex") {
        if (have_vertices) fail_at_line(ctx_, e.line, "a second vertex element");
        have_vertices = true;
        read_vertices(e);
      } else if (e.name == "face") {
        read_faces(e);
      } else if (e.name == "tristrips") {
        read_strips(e);
      } else {
        note_ignored(ctx_, "ply element '" + e.name + "'");
        skip_element(e);
      }
    }
    src_.finish();
    finish_per_vertex_attributes(mesh_);
    return std::move(mesh_);
  }

  // The elements' readers, and their records' (read_ascii_in_chunks reads records).
  void read_vertices(const PlyElement& e) {
    const VertexPlan plan = start_vertices(e);
    for (uint64_t i = 0; i < e.count; ++i) read_vertex(e, plan, i);
  }

  // The element's layout, and room for `count` records.
  VertexPlan start_vertices(const PlyElement& e, uint64_t count = kAll) {
    const VertexPlan plan = plan_vertices(ctx_, e);
    mesh_.layout = plan.layout;
    if (count == kAll) count = e.count;
    mesh_.positions.reserve(size_t(count));
    mesh_.wedge_values.reserve(size_t(count) * size_t(plan.layout.floats_per_wedge()));
    return plan;
  }

  void read_vertex(const PlyElement& e, const VertexPlan& plan, uint64_t i) {
    const AttributeLayout& layout = plan.layout;
    src_.begin_record(e, i);
    double v[kSlots] = {};
    v[kAlpha] = 1.0;
    for (size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& p = e.properties[k];
      if (p.is_list) {
        const uint64_t n = src_.list_count(p);
        for (uint64_t j = 0; j < n; ++j) src_.skip(p.type);
      } else if (plan.slot[k] == kSkip) {
        src_.skip(p.type);
      } else {
        v[plan.slot[k]] = src_.scalar(p.type) / plan.divisor[k];
      }
    }
    mesh_.positions.push_back({v[kX], v[kY], v[kZ]});
    check_finite_position(ctx_, mesh_.positions.back(), "vertex " + std::to_string(i), 0);
    if (layout.normals)
      for (int c : {kNx, kNy, kNz}) mesh_.wedge_values.push_back(float(v[c]));
    if (layout.texcoords)
      for (int c : {kS, kT}) mesh_.wedge_values.push_back(float(v[c]));
    if (layout.colors)
      for (int c : {kRed, kGreen, kBlue, kAlpha}) mesh_.wedge_values.push_back(float(v[c]));
  }

  // Reads one index of `record` and checks it; -1 is allowed when `allow_restart`.
  int64_t read_index(const PlyProperty& p, const PlyElement& e, uint64_t record,
                     bool allow_restart) {
    const uint64_t at = src_.mark();
    const int64_t index = src_.integer(p.type);
    if (index >= 0 && uint64_t(index) < vertex_count_) return index;
    if (index == -1 && allow_restart) return index;
    src_.fail_at(at, record_name(e, record) + " has vertex index " + std::to_string(index) +
                         " but the file has " + std::to_string(vertex_count_) + " vertices");
  }

  void add_triangle(VertexId a, VertexId b, VertexId c) {
    if (mesh_.faces.size() >= ctx_.max_faces())
      fail_limit(ctx_, "more than the limit of " + std::to_string(ctx_.max_faces()) + " faces");
    mesh_.faces.push_back({a, b, c});
  }

  // Calls visit(list property, record index) once per record of `e` at its vertex index
  // list, skipping the record's other properties: faces and strips differ only in the visit.
  template <typename Visit>
  void for_each_index_list(const PlyElement& e, Visit visit) {
    const int list = index_list(ctx_, e);
    for (uint64_t i = 0; i < e.count; ++i) {
      src_.begin_record(e, i);
      for (size_t k = 0; k < e.properties.size(); ++k) {
        if (int(k) == list)
          visit(e.properties[k], i);
        else
          skip_property(e.properties[k]);
      }
    }
  }

  void read_faces(const PlyElement& e) {
    mesh_.faces.reserve(mesh_.faces.size() + size_t(e.count));
    for_each_index_list(e, [&](const PlyProperty& p, uint64_t i) { read_face(e, p, i); });
  }

  // Face record i's vertex index list (the source at its count, the record begun),
  // fan-split into triangles.
  void read_face(const PlyElement& e, const PlyProperty& p, uint64_t i) {
    ReadReport& report = *ctx_.report;
    const uint64_t at = src_.mark();
    const uint64_t n = src_.list_count(p);
    if (n < 3)
      src_.fail_at(
          at, record_name(e, i) + " has " + std::to_string(n) + " vertices, at least 3 needed");
    const VertexId first = VertexId(read_index(p, e, i, false));
    VertexId previous = VertexId(read_index(p, e, i, false));
    for (uint64_t j = 2; j < n; ++j) {
      const VertexId current = VertexId(read_index(p, e, i, false));
      add_triangle(first, previous, current);
      previous = current;
    }
    ++report.polygons;
    if (n > 3) ++report.triangulated_polygons;
  }

  void read_strips(const PlyElement& e) {
    ReadReport& report = *ctx_.report;
    for_each_index_list(e, [&](const PlyProperty& p, uint64_t i) {
      const uint64_t n = src_.list_count(p);
      // The last two indices of the current strip and the number of indices in it so far.
      VertexId a = 0, b = 0;
      uint64_t in_strip = 0;
      for (uint64_t j = 0; j < n; ++j) {
        const int64_t index = read_index(p, e, i, true);
        if (index < 0) {
          in_strip = 0;
          continue;
        }
        const VertexId c = VertexId(index);
        if (in_strip >= 2) {
          const bool odd = (in_strip - 2) % 2 == 1;
          if (a == b || b == c || a == c) {
            ++report.strip_degenerates;
          } else {
            if (odd)
              add_triangle(b, a, c);
            else
              add_triangle(a, b, c);
            ++report.strip_triangles;
          }
        }
        a = b;
        b = c;
        ++in_strip;
      }
    });
  }

  void skip_property(const PlyProperty& p) {
    if (!p.is_list) return src_.skip(p.type);
    const uint64_t n = src_.list_count(p);
    for (uint64_t j = 0; j < n; ++j) src_.skip(p.type);
  }

  void skip_element(const PlyElement& e) {
    if (e.fixed_record_bytes() != 0) return src_.skip_records(e, e.count);
    if (e.properties.empty()) return;
    for (uint64_t i = 0; i < e.count; ++i) {
      src_.begin_record(e, i);
      for (const PlyProperty& p : e.properties) skip_property(p);
    }
  }

 private:
  const ReadContext& ctx_;
  const PlyHeader& header_;
  Source& src_;
  const uint64_t vertex_count_;
  Mesh mesh_;

 public:
  static constexpr uint64_t kAll = ~uint64_t(0);
  Mesh& mesh() { return mesh_; }
  // The last steps of read() on a mesh joined from chunks (read_ascii_in_chunks).
  static void finish_per_vertex_attributes(Mesh& mesh) {
    if (mesh.layout.any()) {
      mesh.wedge_vertex.resize(mesh.positions.size());
      for (size_t v = 0; v < mesh.wedge_vertex.size(); ++v) mesh.wedge_vertex[v] = VertexId(v);
      mesh.face_wedges.assign(mesh.faces.begin(), mesh.faces.end());
    }
    finish_mesh(mesh);
  }
};

// Refuses, before anything is allocated, counts above the limits and then counts the bytes
// after the header cannot hold.
void check_declared_counts(const ReadContext& ctx, const PlyHeader& header) {
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex")
      check_vertex_limit(ctx, e.count,
                         "the header declares " + std::to_string(e.count) + " vertices");
    if (e.name == "face")
      check_face_limit(ctx, e.count, "the header declares " + std::to_string(e.count) + " faces");
  }
  const bool binary = header.encoding != PlyEncoding::kAscii;
  const uint64_t available = ctx.bytes.size() - header.body_offset;
  // Ascii: the last value needs no separator after it.
  uint64_t budget = binary ? available : available + 1;
  for (const PlyElement& e : header.elements) {
    const uint64_t per_record = e.min_record_bytes(binary);
    if (per_record == 0 || e.count == 0) continue;
    if (e.count > budget / per_record)
      fail_at_line(ctx, e.line,
                   "the header declares " + std::to_string(e.count) + " " + e.name +
                       " elements of at least " + std::to_string(per_record) +
                       " bytes each, but only " + std::to_string(available) +
                       " bytes follow the header");
    budget -= e.count * per_record;
  }
}

template <class Source>
Mesh read_body(const ReadContext& ctx, const PlyHeader& header) {
  uint64_t vertex_count = 0;
  for (const PlyElement& e : header.elements)
    if (e.name == "vertex") vertex_count = e.count;
  Source src(ctx, header);
  return PlyBody<Source>(ctx, header, src, vertex_count).read();
}

// The face element's index list where a body may be read in chunks side by side: `loops` of
// more than one chunk, and a vertex element of scalars then a face element of one integer
// index list; null otherwise. Checked without failing: what the one-pass reader refuses, it
// refuses with its message.
const PlyProperty* chunkable_index_list(const ReadContext& ctx, const PlyHeader& header) {
  if (!ctx.loops || ctx.loops->chunks() < 2 || header.elements.size() != 2) return nullptr;
  const PlyElement& vertices = header.elements[0];
  const PlyElement& faces = header.elements[1];
  if (vertices.name != "vertex" || faces.name != "face" || faces.properties.size() != 1)
    return nullptr;
  const PlyProperty& indices = faces.properties[0];
  if (!indices.is_list || (indices.name != "vertex_indices" && indices.name != "vertex_index") ||
      !ply_type_is_integer(indices.type) || !ply_type_is_integer(indices.count_type))
    return nullptr;
  for (const PlyProperty& p : vertices.properties)
    if (p.is_list) return nullptr;
  return &indices;
}

// What a chunk of a body read side by side holds: its records' mesh, and its report.
struct ChunkPart {
  Mesh mesh;
  ReadReport report;
};

// The parts' arrays `member`, one after the other, into `out`, in `loops`' chunks (each copies
// its range of `out` from the parts that hold it).
template <class T>
void join_arrays(std::vector<ChunkPart>& parts, std::vector<T> Mesh::*member, std::vector<T>& out,
                 ChunkedLoops& loops) {
  std::vector<size_t> at(parts.size() + 1, 0);  // where each part's elements begin in `out`
  for (size_t c = 0; c < parts.size(); ++c) at[c + 1] = at[c] + (parts[c].mesh.*member).size();
  resize_touched(out, at.back(), loops);
  loops.run(at.back(), [&](size_t begin, size_t end) {
    size_t c = size_t(std::upper_bound(at.begin(), at.end(), begin) - at.begin()) - 1;
    for (size_t i = begin; i < end; ++c) {
      const std::vector<T>& from = parts[c].mesh.*member;
      const size_t stop = std::min(end, at[c + 1]);
      std::copy(from.begin() + ptrdiff_t(i - at[c]), from.begin() + ptrdiff_t(stop - at[c]),
                out.begin() + ptrdiff_t(i));
      i = stop;
    }
  });
}

// The chunks' meshes one after the other into `mesh`, with their reports; false where the
// faces pass the limit.
bool join_parts(const ReadContext& ctx, std::vector<ChunkPart>& parts, Mesh& mesh) {
  size_t triangles = 0;
  for (const ChunkPart& part : parts) triangles += part.mesh.faces.size();
  if (triangles > ctx.max_faces()) return false;
  ChunkedLoops& loops = *ctx.loops;
  mesh = Mesh{};
  mesh.layout = parts[0].mesh.layout;
  join_arrays(parts, &Mesh::positions, mesh.positions, loops);
  join_arrays(parts, &Mesh::wedge_values, mesh.wedge_values, loops);
  join_arrays(parts, &Mesh::faces, mesh.faces, loops);
  ReadReport& report = *ctx.report;
  for (ChunkPart& part : parts) part.mesh = Mesh{};
  for (const ChunkPart& part : parts) {
    report.polygons += part.report.polygons;
    report.triangulated_polygons += part.report.triangulated_polygons;
    for (const std::string& what : part.report.ignored) note_ignored(ctx, what);
  }
  report.read_in_chunks = true;
  PlyBody<AsciiSource>::finish_per_vertex_attributes(mesh);
  return true;
}

// An ascii body of a vertex element then a face element of one index list, one record per line
// (as writers put them), read in chunks of lines side by side (ReadContext::loops): the same
// mesh as the one-pass reader. False, with nothing read, where the file is otherwise or a
// chunk finds anything amiss (a record off its line, a bad value, a limit): the one-pass
// reader then reads it and names the first problem.
bool read_ascii_in_chunks(const ReadContext& ctx, const PlyHeader& header, Mesh& mesh) {
  const PlyProperty* list = chunkable_index_list(ctx, header);
  if (!list) return false;
  const PlyProperty& indices = *list;
  const PlyElement& vertices = header.elements[0];
  const PlyElement& faces = header.elements[1];
  const char* body = ctx.bytes.data() + header.body_offset;
  const size_t size = ctx.bytes.size() - header.body_offset;
  ChunkedLoops& loops = *ctx.loops;

  // A line belongs to the chunk of bytes its first byte is in: each chunk counts the lines
  // starting in it, then reads them (from its first line's start to the next chunk's).
  const size_t chunks = loops.ranges(size);
  std::vector<uint64_t> first_line(chunks + 1, 0);
  std::vector<const char*> start(chunks + 1, body + size);
  loops.run_indexed(size, [&](size_t chunk, size_t begin, size_t end) {
    uint64_t lines = 0;
    if (begin == 0) {
      lines = 1;
      start[chunk] = body;
    }
    // A newline at i starts a line at i + 1.
    const char* p = body + (begin == 0 ? 0 : begin - 1);
    const char* const last = body + std::min(end, size) - 1;
    while (p < last) {
      p = static_cast<const char*>(std::memchr(p, '\n', size_t(last - p)));
      if (!p) break;
      if (lines == 0) start[chunk] = p + 1;
      ++lines;
      ++p;
    }
    first_line[chunk + 1] = lines;
  });
  for (size_t c = chunks; c-- > 0;)
    if (first_line[c + 1] == 0) start[c] = start[c + 1];  // no line starts in it: empty
  for (size_t c = 0; c < chunks; ++c) first_line[c + 1] += first_line[c];
  const uint64_t records = vertices.count + faces.count;
  if (first_line[chunks] < records) return false;

  std::vector<ChunkPart> parts(chunks);
  std::vector<uint8_t> ok(chunks, 0);
  loops.run_indexed(size, [&](size_t chunk, size_t, size_t) {
    ChunkPart& part = parts[chunk];
    ReadContext local = ctx;
    local.report = &part.report;
    try {
      AsciiSource src(local, start[chunk], start[chunk + 1], header.body_line + first_line[chunk]);
      PlyBody<AsciiSource> reader(local, header, src, vertices.count);
      const uint64_t line_begin = first_line[chunk], line_end = first_line[chunk + 1];
      // Each record must start on its own line.
      auto on_its_line = [&](uint64_t line) { return src.mark() == header.body_line + line; };
      const uint64_t vertex_end = std::min(line_end, vertices.count);
      if (line_begin < vertex_end) {
        const VertexPlan plan = reader.start_vertices(vertices, vertex_end - line_begin);
        for (uint64_t line = line_begin; line < vertex_end; ++line) {
          if (!on_its_line(line)) return;
          reader.read_vertex(vertices, plan, line);
        }
      } else {
        reader.mesh().layout = plan_vertices(local, vertices).layout;
      }
      const uint64_t face_begin = std::max(line_begin, vertices.count);
      const uint64_t face_end = std::min(line_end, records);
      for (uint64_t line = face_begin; line < face_end; ++line) {
        if (!on_its_line(line)) return;
        src.begin_record(faces, line - vertices.count);
        reader.read_face(faces, indices, line - vertices.count);
      }
      src.mark();
      if (src.remaining() > 0) return;  // more than blank lines after the faces
      part.mesh = std::move(reader.mesh());
      ok[chunk] = 1;
    } catch (const Error&) {
      // The one-pass reader names it.
    }
  });
  if (std::find(ok.begin(), ok.end(), 0) != ok.end()) return false;
  return join_parts(ctx, parts, mesh);
}

// A binary body of a vertex element of scalars then a face element of one index list of three
// indices in every record (as scanners and writers put them), its records at fixed strides,
// read in chunks of records side by side (ReadContext::loops): the same mesh as the one-pass
// reader. False, with nothing read, where the file is otherwise (a polygon, other properties
// of the faces, bytes after the faces) or a chunk finds anything amiss: the one-pass reader then
// reads it and names the first problem.
template <class Source>
bool read_binary_in_chunks(const ReadContext& ctx, const PlyHeader& header, Mesh& mesh) {
  const PlyProperty* list = chunkable_index_list(ctx, header);
  if (!list) return false;
  const PlyProperty& indices = *list;
  const PlyElement& vertices = header.elements[0];
  const PlyElement& faces = header.elements[1];
  const uint64_t vertex_bytes = vertices.fixed_record_bytes();
  const uint64_t count_bytes = ply_type_size(indices.count_type);
  const uint64_t face_bytes = count_bytes + 3 * uint64_t(ply_type_size(indices.type));
  const char* body = ctx.bytes.data() + header.body_offset;
  const uint64_t size = ctx.bytes.size() - header.body_offset;
  // (check_declared_counts bounds both counts by the body's size: no overflow)
  const uint64_t faces_at = vertices.count * vertex_bytes;
  if (faces_at + faces.count * face_bytes != size) return false;

  ChunkedLoops& loops = *ctx.loops;
  const uint64_t records = vertices.count + faces.count;
  auto record_at = [&](uint64_t record) {
    return body + (record < vertices.count ? record * vertex_bytes
                                           : faces_at + (record - vertices.count) * face_bytes);
  };
  const size_t chunks = loops.ranges(records);
  std::vector<ChunkPart> parts(chunks);
  std::vector<uint8_t> ok(chunks, 0);
  loops.run_indexed(records, [&](size_t chunk, size_t begin, size_t end) {
    ChunkPart& part = parts[chunk];
    ReadContext local = ctx;
    local.report = &part.report;
    try {
      Source src(local, record_at(begin), record_at(end));
      PlyBody<Source> reader(local, header, src, vertices.count);
      const uint64_t vertex_end = std::min<uint64_t>(end, vertices.count);
      if (begin < vertex_end) {
        const VertexPlan plan = reader.start_vertices(vertices, vertex_end - begin);
        for (uint64_t i = begin; i < vertex_end; ++i) reader.read_vertex(vertices, plan, i);
      } else {
        reader.mesh().layout = plan_vertices(local, vertices).layout;
      }
      for (uint64_t record = std::max<uint64_t>(begin, vertices.count); record < end; ++record) {
        const uint64_t face = record - vertices.count;
        Source count(local, record_at(record), record_at(record) + count_bytes);
        count.begin_record(faces, face);
        if (count.integer(indices.count_type) != 3) return;  // a polygon: strides do not hold
        src.begin_record(faces, face);
        reader.read_face(faces, indices, face);
      }
      if (src.remaining() > 0) return;
      part.mesh = std::move(reader.mesh());
      ok[chunk] = 1;
    } catch (const Error&) {
      // The one-pass reader names it.
    }
  });
  if (std::find(ok.begin(), ok.end(), 0) != ok.end()) return false;
  return join_parts(ctx, parts, mesh);
}

}  // namespace

Mesh read_ply(const ReadContext& ctx) {
  ReadReport& report = *ctx.report;
  report.format = MeshFormat::kPly;
  const PlyHeader header = parse_ply_header(ctx);
  check_declared_counts(ctx, header);
  constexpr bool kLittleHost = std::endian::native == std::endian::little;
  switch (header.encoding) {
    case PlyEncoding::kAscii: {
      report.encoding = "ascii";
      Mesh mesh;
      if (read_ascii_in_chunks(ctx, header, mesh)) return mesh;
      return read_body<AsciiSource>(ctx, header);
    }
    case PlyEncoding::kBinaryLittleEndian: {
      report.encoding = "binary_little_endian";
      Mesh mesh;
      if (read_binary_in_chunks<BinarySource<!kLittleHost>>(ctx, header, mesh)) return mesh;
      return read_body<BinarySource<!kLittleHost>>(ctx, header);
    }
    case PlyEncoding::kBinaryBigEndian: {
      report.encoding = "binary_big_endian";
      Mesh mesh;
      if (read_binary_in_chunks<BinarySource<kLittleHost>>(ctx, header, mesh)) return mesh;
      return read_body<BinarySource<kLittleHost>>(ctx, header);
    }
  }
  fail(ctx, "unknown PLY encoding");
}

}  // namespace parapm::io
