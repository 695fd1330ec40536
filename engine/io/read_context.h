// What every format reader shares: the bytes and the name of the file being read, the limits,
// the report, and the one way to fail ("name: line 12: ..." / "name: byte 1234: ..."), so that
// messages look alike whatever the format. Internal to engine/io.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "io/mesh_io.h"

namespace parapm::io {

struct ReadContext {
  std::string_view bytes;  // the whole file, decompressed
  std::string name;        // for messages
  bool gzip = false;       // byte offsets are then offsets into the decompressed data
  ReadLimits limits;
  ReadReport* report = nullptr;   // never null while reading
  ChunkedLoops* loops = nullptr;  // where a reader may read in chunks side by side; may be null

  // Limits clamped to what 32-bit ids can hold (kNoId is reserved).
  uint64_t max_vertices() const;
  uint64_t max_faces() const;
};

// Errors (all kInvalidInput). `what` is a sentence fragment without the file name.
[[noreturn]] void fail(const ReadContext& ctx, const std::string& what);
[[noreturn]] void fail_at_line(const ReadContext& ctx, uint64_t line, const std::string& what);
[[noreturn]] void fail_at_byte(const ReadContext& ctx, uint64_t offset, const std::string& what);
// kResourceExhausted.
[[noreturn]] void fail_limit(const ReadContext& ctx, const std::string& what);

// Refuses (kResourceExhausted) a count above the vertex / triangle limit. `what` names the
// count in the message, e.g. "the header declares 10 vertices".
void check_vertex_limit(const ReadContext& ctx, uint64_t count, const std::string& what);
void check_face_limit(const ReadContext& ctx, uint64_t count, const std::string& what);

// Refuses (kInvalidInput) a position with a NaN or infinite coordinate, naming it as `what`
// ("vertex 12", numbered as the format numbers it), at `line` when the format has lines (0:
// none).
void check_finite_position(const ReadContext& ctx, const Vec3& p, const std::string& what,
                           uint64_t line);

// Adds `what` to report->ignored unless it is already there.
void note_ignored(const ReadContext& ctx, const std::string& what);

// A token for a message: quoted, at most 40 characters, non-printable bytes as \xNN.
std::string quote(std::string_view token);

// The last step of every reader: derived flags (positions_are_float).
void finish_mesh(Mesh& mesh);

}  // namespace parapm::io
