// The .pm file: a Progressive Mesh in a versioned little-endian binary format, written to be
// streamed (header and base mesh first, then one vsplit record after the other, each
// decodable as soon as it arrives). docs/PM-FORMAT.md specifies it field by field.
//
// Readers take untrusted input: the header's counts are checked against the bytes that can
// follow before anything is allocated, every id is range-checked when its record is read,
// two CRC-32s (header + base mesh; splits + tail) catch the rest, and every failure is an
// Error(kInvalidInput) naming the byte offset. read_pm() also runs validate_pm().
#pragma once

#include <cstdint>
#include <istream>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "mesh/mesh.h"
#include "pm/progressive_mesh.h"
#include "util/chunked_loops.h"

namespace parapm {

class ByteReader;

struct PmHeader {
  uint32_t version = 0;
  bool positions_float64 = false;  // else float32 (then base.positions_are_float)
  AttributeLayout layout;
  bool has_input_vertex_order = false;
  bool has_input_face_order = false;
  uint32_t base_vertices = 0;
  uint32_t base_faces = 0;
  uint32_t base_wedges = 0;
  uint32_t splits = 0;
  uint32_t full_vertices = 0;
  uint32_t full_faces = 0;
  uint32_t full_wedges = 0;
  uint32_t vertex_copies = 0;
  uint64_t input_vertices = 0;
  uint64_t input_faces = 0;
  double seconds = 0;
  Box box;  // of every position at every level (pm_bounding_box)
  std::string metric;
  uint64_t size = 0;  // bytes of the header
};

// One split as read from a stream, with the wedge data it carries.
struct PmSplitRecord {
  VertexSplit split;  // wedge_changes_begin = 0, wedge_changes_count = wedge_changes.size()
  std::vector<float> new_wedge_values;     // floats_per_wedge per new wedge
  std::vector<WedgeChange> wedge_changes;  // values_offset into wedge_change_values
  std::vector<float> wedge_change_values;  // per change: coarse values, then fine values
};

// What follows the splits.
struct PmTail {
  std::vector<std::pair<VertexId, VertexId>> vertex_copies;
  std::vector<uint32_t> input_vertex_order;
  std::vector<uint32_t> input_face_order;
};

// Reads a .pm stream part by part: the constructor reads and checks the header, then
// read_base(), then next_split() until it returns false, then read_tail(). A client of a
// network stream may stop after any split. The reader keeps the current positions and wedge
// values (it needs them to decode deltas), O(vertices + wedges) memory.
class PmReader {
 public:
  // kWholeFile: the stream holds a whole .pm (a file, a complete download); when its size is
  // known, counts the rest of the file cannot hold are refused at once. kPartialStream: the
  // stream may end after any split (a vsplit stream cut at a level); its size is ignored and
  // buffers grow only as records arrive.
  enum class Input { kWholeFile, kPartialStream };
  // `name` is used in messages. Throws Error(kInvalidInput) for a bad header.
  explicit PmReader(std::istream& in, std::string name = "pm stream",
                    Input input = Input::kWholeFile);
  ~PmReader();
  PmReader(const PmReader&) = delete;
  PmReader& operator=(const PmReader&) = delete;

  const PmHeader& header() const { return header_; }
  // Bytes in the stream, when it is a seekable whole file; nullopt for a partial stream.
  std::optional<uint64_t> stream_size() const;
  Mesh read_base();
  // Reads split splits_read(); false once the header's count has been read.
  bool next_split(PmSplitRecord& record);
  size_t splits_read() const { return splits_read_; }
  // Bytes consumed so far: after read_base(), where the splits begin; after next_split(),
  // where the next one begins (a server cuts a stream of records at these offsets).
  uint64_t offset() const;
  // True when the stream has no more bytes (a partial stream cut after a split ends here).
  bool at_end();
  // After the last split: copies, orders, the final checksum and the end of the data.
  PmTail read_tail();
  // Positions at level splits_read().
  const std::vector<Vec3>& positions() const { return positions_; }

 private:
  void read_header();

  std::unique_ptr<ByteReader> in_;
  PmHeader header_;
  bool base_read_ = false;
  size_t splits_read_ = 0;
  std::vector<Vec3> positions_;
  std::vector<float> wedge_values_;
  std::vector<uint32_t> changed_in_;  // per wedge: 1 + the last split that changed it
  uint64_t wedges_ = 0;
  uint64_t faces_ = 0;
  float previous_error_ = 0;
};

// Writes `pm` (validate_pm() first: an invalid PM throws Error(kInvalidInput) and nothing
// is written). Positions are float32 when pm.base.positions_are_float, else float64.
// `split_offsets`, when given, gets where each split begins, then where the last one ends:
// the offsets PmReader::offset() gives after read_base() and after each next_split().
void write_pm(const ProgressiveMesh& pm, std::ostream& out,
              std::vector<uint64_t>* split_offsets = nullptr);
void write_pm_file(const ProgressiveMesh& pm, const std::string& path);
// The same bytes, the splits encoded in `loops`' chunks side by side (and the bounding box
// found in them): what a parallel build's process writes on its threads.
void write_pm(const ProgressiveMesh& pm, std::ostream& out, ChunkedLoops& loops,
              std::vector<uint64_t>* split_offsets = nullptr);
void write_pm_file(const ProgressiveMesh& pm, const std::string& path, ChunkedLoops& loops);
// Bytes write_pm() would write.
size_t pm_encoded_size(const ProgressiveMesh& pm);

ProgressiveMesh read_pm(std::istream& in, const std::string& name = "pm stream");
// Appends a split read by PmReader to `pm` (whose base came from the same reader): a client of
// a vsplit stream holds a PM of the levels it has so far (level_of_detail works up to them).
void append_split(ProgressiveMesh& pm, const PmSplitRecord& record);
ProgressiveMesh read_pm_file(const std::string& path);

// Bounding box of every position at every level: the base positions, vs_after and vt_after of
// every split (the header's box; a viewer can frame any level with it).
Box pm_bounding_box(const ProgressiveMesh& pm);
Box pm_bounding_box(const ProgressiveMesh& pm, ChunkedLoops& loops);  // the same box

}  // namespace parapm
