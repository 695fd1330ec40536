// Reading and writing meshes: OBJ, PLY (ascii, binary little/big endian, face lists and
// triangle strips), OFF, STL (ascii, binary), any of them gzip-compressed.
//
// Readers are written for untrusted input: every count a header declares is checked against
// the bytes actually present before anything is allocated, every index is range-checked, and
// every failure is an Error(kInvalidInput) naming the file and the line (text) or byte offset
// (binary) and what is wrong. Readers do not repair: degenerate, duplicate or non-manifold
// faces come out as they are in the file, for repair_mesh() to handle and report.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

enum class MeshFormat { kUnknown, kObj, kPly, kOff, kStl };

struct ReadLimits {
  // Decompressed input larger than this is refused (kResourceExhausted).
  uint64_t max_bytes = uint64_t(8) << 30;
  // Declared or found element counts larger than these are refused (kResourceExhausted).
  uint64_t max_vertices = uint64_t(1) << 31;
  uint64_t max_faces = uint64_t(1) << 31;
};

// What the reader saw that is not an error, for the load report.
struct ReadReport {
  MeshFormat format = MeshFormat::kUnknown;
  bool gzip = false;
  uint64_t input_bytes = 0;        // after decompression
  uint64_t polygons = 0;           // faces as stored (before fan triangulation)
  uint64_t triangulated_polygons = 0;  // polygons with more than 3 corners, fan-split
  uint64_t strip_triangles = 0;    // triangles that came from PLY triangle strips
  uint64_t welded_vertices = 0;    // STL: corners merged into shared vertices by exact equality
  std::vector<std::string> ignored;  // e.g. "ply vertex property 'confidence'", "obj groups"
};

MeshFormat format_from_name(const std::string& path);  // by extension, ".gz" ignored
const char* format_name(MeshFormat format);

// Reads a whole file (gzip detected by its magic bytes, whatever the name).
Mesh read_mesh(const std::string& path, ReadReport* report = nullptr,
               const ReadLimits& limits = {});
// Reads from memory; `name` is used in messages and for the format when it has an extension,
// otherwise the content decides.
Mesh read_mesh_from_memory(const std::string& bytes, const std::string& name,
                           ReadReport* report = nullptr, const ReadLimits& limits = {});

struct WriteOptions {
  bool ascii = false;  // PLY: ascii instead of binary little endian
};
// Writes OBJ or PLY, chosen by the extension of `path` (".gz" appended compresses).
void write_mesh(const Mesh& mesh, const std::string& path, const WriteOptions& options = {});

}  // namespace parapm
