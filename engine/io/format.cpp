// Telling the format of a mesh file: by the extension of its name (".gz" ignored) and, when
// the name says nothing, by its first bytes.
#include <algorithm>
#include <cctype>
#include <string>

#include "io/formats.h"
#include "io/mesh_io.h"
#include "io/read_context.h"
#include "io/text_scanner.h"

namespace parapm {
namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

MeshFormat format_from_name(const std::string& path) {
  std::string name = lower(path.substr(path.find_last_of("/\\") + 1));
  if (name.size() > 3 && name.compare(name.size() - 3, 3, ".gz") == 0) name.resize(name.size() - 3);
  const size_t dot = name.find_last_of('.');
  if (dot == std::string::npos) return MeshFormat::kUnknown;
  const std::string ext = name.substr(dot + 1);
  if (ext == "obj") return MeshFormat::kObj;
  if (ext == "ply") return MeshFormat::kPly;
  if (ext == "off") return MeshFormat::kOff;
  if (ext == "stl") return MeshFormat::kStl;
  return MeshFormat::kUnknown;
}

const char* format_name(MeshFormat format) {
  switch (format) {
    case MeshFormat::kObj:
      return "obj";
    case MeshFormat::kPly:
      return "ply";
    case MeshFormat::kOff:
      return "off";
    case MeshFormat::kStl:
      return "stl";
    case MeshFormat::kUnknown:
      return "unknown";
  }
  return "unknown";
}

namespace io {

MeshFormat detect_format(std::string_view bytes) {
  // Magic bytes first: "ply" on its own line, then a binary STL whose size matches its count
  // (it may start with any header, even "solid").
  if (bytes.size() >= 4 && bytes.substr(0, 3) == "ply" && (bytes[3] == '\n' || bytes[3] == '\r'))
    return MeshFormat::kPly;
  if (stl_binary_size_matches(bytes)) return MeshFormat::kStl;

  // Text formats: the first keyword after blank and '#' comment lines.
  TextScanner scan(bytes.substr(0, std::min<size_t>(bytes.size(), 1 << 16)));
  for (;;) {
    scan.skip_space();
    if (scan.at_end()) return MeshFormat::kUnknown;
    if (scan.peek() != '#') break;
    scan.next_line();
  }
  const std::string_view first = scan.token();
  if (is_off_keyword(first)) return MeshFormat::kOff;
  if (equals_ignore_case(first, "solid")) return MeshFormat::kStl;
  for (std::string_view keyword :
       {"v", "vt", "vn", "vp", "f", "l", "p", "g", "o", "s", "usemtl", "mtllib"})
    if (first == keyword) return MeshFormat::kObj;
  return MeshFormat::kUnknown;
}

void check_mesh_start(const ReadContext& ctx, MeshFormat format, std::string_view start) {
  switch (format) {
    case MeshFormat::kPly:
      if (start.size() >= 4 && (start.substr(0, 4) == "ply\n" || start.substr(0, 4) == "ply\r"))
        return;
      fail(ctx, "not a PLY file: the first line is not 'ply'");
    case MeshFormat::kOff:
      if (detect_format(start) == MeshFormat::kOff) return;
      fail(ctx, "not an OFF file: its first keyword is not OFF");
    case MeshFormat::kObj:
      // OBJ statements are many and open-ended: refuse only what is not text at all.
      if (const size_t nul = start.find('\0'); nul != std::string_view::npos)
        fail_at_byte(ctx, nul, "not an OBJ file: a NUL byte (binary data, not text)");
      return;
    case MeshFormat::kStl:
      if (stl_start_fits(start)) return;
      fail(ctx,
           "not an STL file: it does not start with 'solid' and its binary header declares "
           "fewer triangles than the data that follows");
    case MeshFormat::kUnknown:
      if (detect_format(start) != MeshFormat::kUnknown || stl_start_fits(start)) return;
      fail(ctx,
           "neither the name nor the content tells the format (expected OBJ, PLY, OFF or STL)");
  }
}

}  // namespace io
}  // namespace parapm
