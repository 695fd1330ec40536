// Parsing a PLY header (see ply_format.h for the grammar).
#include <string>

#include "io/ply_format.h"
#include "io/text_scanner.h"

namespace parapm::io {
namespace {

struct TypeName {
  std::string_view name;
  PlyType type;
};
constexpr TypeName kTypeNames[] = {
    {"char", PlyType::kInt8},      {"uchar", PlyType::kUint8},    {"short", PlyType::kInt16},
    {"ushort", PlyType::kUint16},  {"int", PlyType::kInt32},      {"uint", PlyType::kUint32},
    {"float", PlyType::kFloat32},  {"double", PlyType::kFloat64}, {"int8", PlyType::kInt8},
    {"uint8", PlyType::kUint8},    {"int16", PlyType::kInt16},    {"uint16", PlyType::kUint16},
    {"int32", PlyType::kInt32},    {"uint32", PlyType::kUint32},  {"float32", PlyType::kFloat32},
    {"float64", PlyType::kFloat64}};

}  // namespace

bool parse_ply_type(std::string_view name, PlyType* type) {
  for (const TypeName& t : kTypeNames)
    if (t.name == name) {
      *type = t.type;
      return true;
    }
  return false;
}

const char* ply_type_name(PlyType type) {
  for (const TypeName& t : kTypeNames)
    if (t.type == type) return t.name.data();  // the first 8 entries are NUL-terminated literals
  return "?";
}

uint64_t PlyElement::min_record_bytes(bool binary) const {
  uint64_t bytes = 0;
  for (const PlyProperty& p : properties)
    bytes += binary ? uint64_t(ply_type_size(p.is_list ? p.count_type : p.type)) : 2;
  return bytes;
}

uint64_t PlyElement::fixed_record_bytes() const {
  uint64_t bytes = 0;
  for (const PlyProperty& p : properties) {
    if (p.is_list) return 0;
    bytes += uint64_t(ply_type_size(p.type));
  }
  return bytes;
}

PlyHeader parse_ply_header(const ReadContext& ctx) {
  TextScanner s(ctx.bytes);
  if (s.rest_of_line() != "ply") fail(ctx, "not a PLY file: the first line is not 'ply'");
  s.next_line();

  PlyHeader header;
  bool have_format = false;
  for (;;) {
    if (s.at_end()) fail(ctx, "the PLY header has no end_header line");
    const uint64_t line = s.line();
    const std::string_view statement = s.rest_of_line();
    s.skip_blanks();
    const std::string_view keyword = s.token();
    if (keyword == "end_header") {
      s.next_line();
      header.body_offset = size_t(s.pos() - ctx.bytes.data());
      header.body_line = s.line();
      break;
    }
    if (keyword == "format") {
      const std::string_view encoding = s.token_in_line();
      const std::string_view version = s.token_in_line();
      if (encoding == "ascii")
        header.encoding = PlyEncoding::kAscii;
      else if (encoding == "binary_little_endian")
        header.encoding = PlyEncoding::kBinaryLittleEndian;
      else if (encoding == "binary_big_endian")
        header.encoding = PlyEncoding::kBinaryBigEndian;
      else
        fail_at_line(ctx, line, "unknown PLY format " + quote(encoding));
      if (version != "1.0") note_ignored(ctx, "ply format version " + quote(version));
      have_format = true;
    } else if (keyword == "element") {
      PlyElement element;
      element.name = std::string(s.token_in_line());
      element.line = line;
      s.skip_blanks();
      if (element.name.empty() || !s.read(element.count))
        fail_at_line(ctx, line, "expected 'element <name> <count>', found " + quote(statement));
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) fail_at_line(ctx, line, "a property comes before any element");
      PlyProperty property;
      std::string_view type = s.token_in_line();
      if (type == "list") {
        property.is_list = true;
        const std::string_view count_type = s.token_in_line();
        if (!parse_ply_type(count_type, &property.count_type))
          fail_at_line(ctx, line, "unknown PLY list count type " + quote(count_type));
        if (!ply_type_is_integer(property.count_type))
          fail_at_line(ctx, line,
                       "a PLY list count type must be an integer type, not " + quote(count_type));
        type = s.token_in_line();
      }
      if (!parse_ply_type(type, &property.type))
        fail_at_line(ctx, line, "unknown PLY property type " + quote(type));
      property.name = std::string(s.token_in_line());
      if (property.name.empty()) fail_at_line(ctx, line, "a property has no name");
      header.elements.back().properties.push_back(std::move(property));
    } else if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) {
      // nothing to do
    } else {
      note_ignored(ctx, "ply header line " + quote(statement));
    }
    s.next_line();
  }
  if (!have_format) fail(ctx, "the PLY header has no format line");
  return header;
}

}  // namespace parapm::io
