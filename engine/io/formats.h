// The per-format entry points behind read_mesh() and write_mesh(). Internal to engine/io: each
// reader takes the whole decompressed file and fills the report; each writer returns the file's
// bytes (uncompressed).
#pragma once

#include <string>
#include <string_view>

#include "io/mesh_io.h"
#include "io/read_context.h"

namespace parapm::io {

Mesh read_obj(const ReadContext& ctx);  // obj_reader.cpp
Mesh read_ply(const ReadContext& ctx);  // ply_reader.cpp
Mesh read_off(const ReadContext& ctx);  // off_reader.cpp
Mesh read_stl(const ReadContext& ctx);  // stl_reader.cpp

// The format of a file from its first bytes, kUnknown when none fits (format.cpp).
MeshFormat detect_format(std::string_view bytes);
// Whether a token is an OFF header keyword: [ST][C][N][4][n]OFF (off_reader.cpp).
bool is_off_keyword(std::string_view token);
// Whether the size is exactly 84 + 50 * (the count at byte 80): a binary STL (stl_reader.cpp).
bool stl_binary_size_matches(std::string_view bytes);
// Whether `start`, the first bytes of a file, can begin an STL: ascii ('solid'), or binary
// whose declared size (84 + 50 * the count at byte 80) is at least what is there (stl_reader.cpp).
bool stl_start_fits(std::string_view start);

// Throws what the format's reader would (kInvalidInput) when `start`, the first bytes of a
// file whose length is not known yet, cannot begin a mesh file of `format` (kUnknown: of any
// format): so that a gzip bomb of zeros stops after its first bytes (format.cpp).
void check_mesh_start(const ReadContext& ctx, MeshFormat format, std::string_view start);

// Gives every face corner and wedge of a vertex the first vertex at exactly the same place
// (bit-identical coordinates, -0 as +0): the pieces of a surface stored unwelded (a triangle
// soup, parts that meet at duplicated vertices) become one surface, as STL's reader makes its
// corners. The merged vertices stay, unused; wedges keep their values, so attributes that
// differed across a seam stay per corner. Returns the number of vertices merged (weld.cpp).
// In `loops`' chunks when given (the same result).
uint64_t weld_coincident_vertices(Mesh& mesh, ChunkedLoops* loops = nullptr);

// Throws kInvalidInput unless faces, wedges and attribute arrays are consistent (mesh_io.cpp).
void check_writable(const Mesh& mesh);
std::string write_obj(const Mesh& mesh);              // obj_writer.cpp
std::string write_ply(const Mesh& mesh, bool ascii);  // ply_writer.cpp
uint64_t binary_ply_size(const Mesh& mesh);           // write_ply(mesh, false).size()

}  // namespace parapm::io
