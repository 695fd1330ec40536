// The PLY format as data: property types, the parsed header, and the one header parser the
// reader uses (the writer only needs the type names). Internal to engine/io.
//
// Header grammar accepted (one statement per line, '\n' or "\r\n"):
//   ply
//   format ascii|binary_little_endian|binary_big_endian 1.0
//   comment ... | obj_info ...
//   element <name> <count>
//   property <type> <name> | property list <count type> <item type> <name>
//   end_header
// Types: char uchar short ushort int uint float double and int8 uint8 int16 uint16 int32
// uint32 float32 float64. Other header lines are ignored and listed in the report (Blender 2.4
// wrote a bare "Created by Blender3D ..." line).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "io/read_context.h"

namespace parapm::io {

enum class PlyType : uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kFloat32,
  kFloat64
};

bool parse_ply_type(std::string_view name, PlyType* type);
const char* ply_type_name(PlyType type);  // "char", "uchar", ... "double"
inline int ply_type_size(PlyType type) {
  switch (type) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 8;
}
inline bool ply_type_is_integer(PlyType type) {
  return type != PlyType::kFloat32 && type != PlyType::kFloat64;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;  // the item type for a list
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;  // lists only
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  uint64_t line = 0;  // of its "element" statement

  // The fewest bytes one record can take: binary, every scalar and list count (lists may be
  // empty); ascii, one digit and one separator per scalar and list count.
  uint64_t min_record_bytes(bool binary) const;
  // The exact record size when no property is a list, else 0.
  uint64_t fixed_record_bytes() const;
};

enum class PlyEncoding { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::kAscii;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;  // first byte after the end_header line
  uint64_t body_line = 0;  // its line number (ascii)
};

// Parses the header at the start of ctx.bytes; throws kInvalidInput naming the line.
PlyHeader parse_ply_header(const ReadContext& ctx);

}  // namespace parapm::io
