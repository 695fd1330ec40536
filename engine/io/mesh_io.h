// Reading and writing meshes: OBJ, PLY (ascii, binary little/big endian, face lists and
// triangle strips), OFF, STL (ascii, binary), any of them gzip-compressed.
//
// Readers are written for untrusted input: every count a header declares is checked against
// the bytes actually present before anything is allocated, every index is range-checked, and
// every failure is an Error(kInvalidInput) naming the file and the line (text) or byte offset
// (binary) and what is wrong. Readers do not repair: degenerate, duplicate or non-manifold
// faces come out as they are in the file, for repair_mesh() to handle and report.
//
// Error codes: kInvalidInput for malformed data ("bad.ply: byte 1234: face 17 has vertex index
// 9999 but the file has 500 vertices"; byte offsets of a gzip file count decompressed bytes),
// kResourceExhausted when a ReadLimits value is exceeded (a declared count is compared with the
// limit first, then with the bytes that follow), kNotFound when the file does not exist, kIo
// when the system fails to read or write it.
//
// Attributes (see the wedge model in mesh/mesh.h):
// - OBJ: each distinct (v, vt, vn) triple used by a face corner is one wedge, numbered in the
//   order of first use. A file where only some corners have a vt (or vn) is common (e.g. a
//   textured part beside an untextured one), so such corners get a wedge with zeros in that
//   channel and are counted in ReadReport::corners_without_texcoord / _normal. Vertex colours
//   ("v x y z r g b [a]") are copied to every wedge of the vertex; a vertex without colour in a
//   file that has some gets opaque white and is counted in vertices_without_color.
// - PLY, OFF: attributes are per vertex, so wedge i is vertex i and face_wedges == faces.
// - STL: no attributes (facet normals are recomputable and ignored).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "util/chunked_loops.h"

namespace parapm {

enum class MeshFormat { kUnknown, kObj, kPly, kOff, kStl };

struct ReadLimits {
  // Decompressed input larger than this is refused (kResourceExhausted). Inflating stops as
  // soon as the limit is passed: a gzip bomb never allocates more than max_bytes + 1 bytes.
  uint64_t max_bytes = uint64_t(8) << 30;
  // Declared or found element counts larger than these are refused (kResourceExhausted).
  // Vertices count positions (and OBJ vt/vn records); faces count triangles after splitting.
  uint64_t max_vertices = uint64_t(1) << 31;
  uint64_t max_faces = uint64_t(1) << 31;
};

// What the reader saw that is not an error, for the load report.
struct ReadReport {
  MeshFormat format = MeshFormat::kUnknown;
  std::string encoding;  // "ascii", "binary_little_endian", "binary_big_endian", "binary"
  bool gzip = false;
  uint64_t input_bytes = 0;            // after decompression
  uint64_t polygons = 0;               // faces as stored (before fan triangulation)
  uint64_t triangulated_polygons = 0;  // polygons with more than 3 corners, fan-split
  uint64_t strip_triangles = 0;        // triangles that came from PLY triangle strips
  uint64_t strip_degenerates = 0;      // PLY strip triangles with a repeated index, not made faces
  // Exactly coincident vertices merged (their faces then use the first at that place): STL, its
  // corners merged into shared vertices; other formats, vertices merged (they stay, unused).
  uint64_t welded_vertices = 0;
  uint64_t corners_without_texcoord = 0;  // OBJ: corners without vt in a file that has vt
  uint64_t corners_without_normal = 0;    // OBJ: corners without vn in a file that has vn
  uint64_t vertices_without_color = 0;    // OBJ: v without colour in a file that has some
  std::vector<std::string> ignored;       // e.g. "ply vertex property 'confidence'", "obj groups"
  bool read_in_chunks = false;            // a PLY body read in chunks side by side (its `loops`)
};

MeshFormat format_from_name(const std::string& path);  // by extension, ".gz" ignored
const char* format_name(MeshFormat format);

// Reads a whole file (gzip detected by its magic bytes, whatever the name). The format comes
// from the extension (".gz" ignored) and, when the name has no known extension, from the
// content. Messages name the file by `path` as given. `loops`: where an ascii PLY body of
// one record per line is read in chunks side by side (the same mesh); null: on this thread.
Mesh read_mesh(const std::string& path, ReadReport* report = nullptr, const ReadLimits& limits = {},
               ChunkedLoops* loops = nullptr);
// Reads from memory; `name` is used in messages and for the format when it has an extension,
// otherwise the content decides.
Mesh read_mesh_from_memory(const std::string& bytes, const std::string& name,
                           ReadReport* report = nullptr, const ReadLimits& limits = {},
                           ChunkedLoops* loops = nullptr);

struct WriteOptions {
  bool ascii = false;  // PLY: ascii instead of binary little endian
};
// Writes OBJ or PLY, chosen by the extension of `path` (".gz" appended compresses with gzip).
// Other extensions are refused (kInvalidInput), and so is a mesh whose indices are out of
// range or whose wedges do not belong to the corners' vertices.
//
// Round trips are exact: read_mesh(write_mesh(m)) has the same positions bit for bit, the
// same faces and the same attribute value at every face corner (colours exactly when they are
// multiples of 1/255, as read from PLY uchar).
// - OBJ: positions and attributes in shortest round-trip decimal; one vt and/or vn line per
//   wedge, faces as v/vt/vn. Colours go on the v lines ("v x y z r g b", plus alpha when one is
//   not 1), so they are per vertex: a vertex takes the colour of its first wedge.
// - PLY: float positions when mesh.positions_are_float (and they are), else double; normals
//   nx ny nz float, texcoords s t float, colours red green blue alpha uchar (round(c * 255)).
//   PLY attributes are per vertex, so the writer emits one PLY vertex per wedge, vertex by
//   vertex (same position for the wedges of one vertex); a mesh with one wedge per vertex in
//   vertex order (as read from PLY) is written with the same vertex numbering. Reading such a
//   file back gives a mesh whose seam vertices are split.
void write_mesh(const Mesh& mesh, const std::string& path, const WriteOptions& options = {});

// The size in bytes of the binary PLY write_mesh would write for `mesh` (a .ply path), without
// writing it: what the CLI compares a .pm's size with. Refuses what write_mesh refuses.
uint64_t binary_ply_size(const Mesh& mesh);

}  // namespace parapm
