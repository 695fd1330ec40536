// Writing the .pm format (docs/PM-FORMAT.md), its file wrappers, and the bounding box the
// header carries. The writer encodes what validate_pm() guarantees: vs_before is the current
// position of vs (so only deltas from it are stored), new wedges are first used in id order
// (so a corner can say "the next new wedge"), and wedge changes' coarse values are the current
// values (so only fine - coarse is stored).
#include "pm/pm_file.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pm/byte_io.h"
#include "pm/float_ordinal.h"
#include "pm/pm_format.h"
#include "util/error.h"

namespace parapm {

namespace fmt = pm_format;

namespace {

// Grows `box` (empty while `first`) to hold p.
void add_to_box(const Vec3& p, Box& box, bool& first) {
  if (first) {
    box.min = box.max = p;
    first = false;
    return;
  }
  for (int k = 0; k < 3; ++k) {
    box.min[k] = std::min(box.min[k], p[k]);
    box.max[k] = std::max(box.max[k], p[k]);
  }
}

}  // namespace

Box pm_bounding_box(const ProgressiveMesh& pm) {
  ChunkedLoops one_thread;
  return pm_bounding_box(pm, one_thread);
}

Box pm_bounding_box(const ProgressiveMesh& pm, ChunkedLoops& loops) {
  Box box;
  bool first = true;
  for (const Vec3& p : pm.base.positions) add_to_box(p, box, first);
  // Per range of splits its own box, joined in order: minima and maxima, the same box.
  const size_t ranges = loops.ranges(pm.splits.size());
  std::vector<Box> boxes(ranges);
  std::vector<uint8_t> empty(ranges, 1);
  loops.run_indexed(pm.splits.size(), [&](size_t range, size_t begin, size_t end) {
    bool none = true;
    for (size_t i = begin; i < end; ++i) {
      add_to_box(pm.splits[i].vs_after, boxes[range], none);
      add_to_box(pm.splits[i].vt_after, boxes[range], none);
    }
    empty[range] = none;
  });
  for (size_t r = 0; r < ranges; ++r)
    if (!empty[r]) {
      add_to_box(boxes[r].min, box, first);
      add_to_box(boxes[r].max, box, first);
    }
  return box;
}

namespace {

uint32_t header_flags(const ProgressiveMesh& pm) {
  const AttributeLayout& layout = pm.base.layout;
  uint32_t flags = 0;
  if (!pm.base.positions_are_float) flags |= fmt::kFlagPositionsFloat64;
  if (layout.normals) flags |= fmt::kFlagNormals;
  if (layout.texcoords) flags |= fmt::kFlagTexcoords;
  if (layout.colors) flags |= fmt::kFlagColors;
  if (!pm.vertex_copies.empty()) flags |= fmt::kFlagVertexCopies;
  if (!pm.input_vertex_order.empty()) flags |= fmt::kFlagInputVertexOrder;
  if (!pm.input_face_order.empty()) flags |= fmt::kFlagInputFaceOrder;
  return flags;
}

void write_position_delta(ByteWriter& out, const Vec3& after, const Vec3& before, bool float32) {
  for (int k = 0; k < 3; ++k) {
    if (float32)
      out.zigzag32(float_delta(float(after[k]), float(before[k])));
    else
      out.zigzag64(double_delta(after[k], before[k]));
  }
}

// Splits [begin, end) of `pm`, the first of them introducing wedge `wedges` and reading new
// wedge values from `next_new_value`; `split_offsets` (when given) gets where each begins in
// `out`.
void write_split_range(const ProgressiveMesh& pm, size_t begin, size_t end, uint64_t wedges,
                       size_t next_new_value, ByteWriter& out,
                       std::vector<uint64_t>* split_offsets) {
  const bool float32 = pm.base.positions_are_float;
  const bool attributes = pm.base.layout.any();
  const size_t fpw = size_t(pm.base.layout.floats_per_wedge());
  for (size_t i = begin; i < end; ++i) {
    const VertexSplit& s = pm.splits[i];
    if (split_offsets) split_offsets->push_back(out.offset());
    out.varint(s.vs);
    out.varint(s.has_fl() ? uint64_t(s.vl) + 1 : 0);
    out.varint(s.has_fr() ? uint64_t(s.vr) + 1 : 0);
    out.f32(s.error);
    write_position_delta(out, s.vs_after, s.vs_before, float32);
    write_position_delta(out, s.vt_after, s.vs_before, float32);
    if (!attributes) continue;
    uint64_t next_new = wedges;
    for (int k = 0; k < 6; ++k) {
      if (!(k < 3 ? s.has_fl() : s.has_fr())) continue;
      const WedgeId w = s.corner_wedges[k];
      if (w == next_new) {  // validate_pm: new wedges are first used in id order
        out.varint(0);
        for (size_t j = 0; j < fpw; ++j) out.f32(pm.new_wedge_values[next_new_value++]);
        ++next_new;
      } else {
        out.varint(uint64_t(w) + 1);
      }
    }
    wedges = next_new;
    out.varint(s.wedge_changes_count);
    for (uint32_t c = 0; c < s.wedge_changes_count; ++c) {
      const WedgeChange& change = pm.wedge_changes[s.wedge_changes_begin + c];
      const float* coarse = pm.wedge_change_values.data() + change.values_offset;
      out.varint(change.wedge);
      for (size_t j = 0; j < fpw; ++j) out.zigzag32(float_delta(coarse[fpw + j], coarse[j]));
    }
  }
}

// Every split, then (with `split_offsets`) where the last one ends. In `loops`' ranges, each
// range into a buffer of its own, from the wedge counts of the splits before it
// (new_wedge_count, which validate_pm checked against the corners), joined in order: the same
// bytes.
void write_splits(const ProgressiveMesh& pm, ByteWriter& out, std::vector<uint64_t>* split_offsets,
                  ChunkedLoops& loops) {
  const size_t n = pm.splits.size();
  const uint64_t base_wedges = pm.base.wedge_count();
  const size_t fpw = size_t(pm.base.layout.floats_per_wedge());
  if (split_offsets) {
    split_offsets->clear();
    split_offsets->reserve(n + 1);
  }
  const size_t ranges = loops.ranges(n);
  if (ranges <= 1) {
    write_split_range(pm, 0, n, base_wedges, 0, out, split_offsets);
  } else {
    std::vector<uint64_t> new_wedges(ranges + 1, 0);  // before each range, once summed
    loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) new_wedges[range + 1] += pm.splits[i].new_wedge_count;
    });
    for (size_t r = 0; r < ranges; ++r) new_wedges[r + 1] += new_wedges[r];
    std::vector<std::string> bytes(ranges);
    std::vector<uint32_t> crcs(ranges);
    std::vector<std::vector<uint64_t>> offsets(ranges);
    loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
      std::ostringstream buffer;
      ByteWriter writer(&buffer);
      write_split_range(pm, begin, end, base_wedges + new_wedges[range],
                        size_t(new_wedges[range]) * fpw, writer,
                        split_offsets ? &offsets[range] : nullptr);
      writer.flush();
      crcs[range] = writer.crc();
      bytes[range] = std::move(buffer).str();
    });
    for (size_t r = 0; r < ranges; ++r) {
      if (split_offsets)
        for (uint64_t offset : offsets[r]) split_offsets->push_back(out.offset() + offset);
      out.bytes_with_crc(bytes[r].data(), bytes[r].size(), crcs[r]);
    }
  }
  if (split_offsets) split_offsets->push_back(out.offset());
}

// The caller has validated `pm` (validate_pm): the encoding relies on its invariants.
void write_all(const ProgressiveMesh& pm, ByteWriter& out, ChunkedLoops& loops,
               std::vector<uint64_t>* split_offsets = nullptr) {
  const Mesh& base = pm.base;
  const bool float32 = base.positions_are_float;
  const bool attributes = base.layout.any();
  const size_t fpw = size_t(base.layout.floats_per_wedge());
  if (pm.info.metric.size() > fmt::kMaxMetricLength)
    throw_invalid("the metric name is longer than " + std::to_string(fmt::kMaxMetricLength) +
                  " bytes");

  // Header.
  out.bytes(fmt::kMagic, sizeof fmt::kMagic);
  out.u32(fmt::kVersion);
  out.u32(header_flags(pm));
  out.u32(uint32_t(base.vertex_count()));
  out.u32(uint32_t(base.face_count()));
  out.u32(uint32_t(attributes ? base.wedge_count() : 0));
  out.u32(uint32_t(pm.splits.size()));
  out.u32(uint32_t(pm.full_vertex_count()));
  out.u32(uint32_t(pm.full_face_count()));
  out.u32(uint32_t(attributes ? pm.full_wedge_count() : 0));
  out.u32(uint32_t(pm.vertex_copies.size()));
  out.u64(pm.info.input_vertices);
  out.u64(pm.info.input_faces);
  const Box box = pm_bounding_box(pm, loops);
  for (double c : box.min) out.f64(c);
  for (double c : box.max) out.f64(c);
  out.u32(uint32_t(pm.info.metric.size()));
  out.bytes(pm.info.metric.data(), pm.info.metric.size());

  // Base mesh.
  for (const Vec3& p : base.positions)
    for (double c : p) float32 ? out.f32(float(c)) : out.f64(c);
  for (const Triangle& t : base.faces)
    for (VertexId v : t) out.u32(v);
  if (attributes) {
    for (const auto& corners : base.face_wedges)
      for (WedgeId w : corners) out.u32(w);
    for (WedgeId w = 0; w < base.wedge_count(); ++w) {
      out.u32(base.wedge_vertex[w]);
      for (size_t k = 0; k < fpw; ++k) out.f32(base.wedge_values[w * fpw + k]);
    }
  }
  out.u32(out.crc());
  out.reset_crc();

  // Splits.
  write_splits(pm, out, split_offsets, loops);

  // Tail.
  for (const auto& [copy, original] : pm.vertex_copies) {
    out.u32(copy);
    out.u32(original);
  }
  for (uint32_t v : pm.input_vertex_order) out.u32(v);
  for (uint32_t f : pm.input_face_order) out.u32(f);
  out.u32(out.crc());
  out.flush();
}

}  // namespace

void write_pm(const ProgressiveMesh& pm, std::ostream& out, std::vector<uint64_t>* split_offsets) {
  ChunkedLoops one_thread;
  write_pm(pm, out, one_thread, split_offsets);
}

void write_pm(const ProgressiveMesh& pm, std::ostream& out, ChunkedLoops& loops,
              std::vector<uint64_t>* split_offsets) {
  validate_pm(pm, loops);
  ByteWriter writer(&out);
  write_all(pm, writer, loops, split_offsets);
}

size_t pm_encoded_size(const ProgressiveMesh& pm) {
  validate_pm(pm);
  ByteWriter counter(nullptr);
  ChunkedLoops one_thread;
  write_all(pm, counter, one_thread);
  return size_t(counter.offset());
}

void write_pm_file(const ProgressiveMesh& pm, const std::string& path) {
  ChunkedLoops one_thread;
  write_pm_file(pm, path, one_thread);
}

void write_pm_file(const ProgressiveMesh& pm, const std::string& path, ChunkedLoops& loops) {
  validate_pm(pm, loops);  // before the file is created
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error(ErrorCode::kIo, "cannot open " + path + " for writing");
  try {
    ByteWriter writer(&out);
    write_all(pm, writer, loops);
    out.close();
    if (!out) throw Error(ErrorCode::kIo, "writing " + path + " failed");
  } catch (const Error& e) {
    out.close();
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
    if (e.code() == ErrorCode::kIo) throw Error(ErrorCode::kIo, "writing " + path + " failed");
    throw;
  }
}

ProgressiveMesh read_pm_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw Error(ErrorCode::kNotFound, path + ": no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, path + ": cannot open for reading");
  return read_pm(in, path);
}

}  // namespace parapm
