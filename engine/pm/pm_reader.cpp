// Reading the .pm format (docs/PM-FORMAT.md): PmReader, the part-by-part reader a stream of
// vsplits uses, and read_pm(), which assembles a ProgressiveMesh with it and validates it.
// Every count is checked against the bytes that can follow before it sizes an allocation;
// with a stream of unknown size, buffers grow only as elements actually arrive.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>

#include "pm/byte_io.h"
#include "pm/float_ordinal.h"
#include "pm/pm_file.h"
#include "pm/pm_format.h"
#include "util/error.h"

namespace parapm {

namespace fmt = pm_format;

namespace {

std::string str(uint64_t value) { return std::to_string(value); }

// Reserve for `count` elements the header declared: all of them when the size is known (the
// caller checked they fit), a bounded first chunk otherwise.
template <typename T>
void reserve_declared(std::vector<T>& v, uint64_t count, const ByteReader& in) {
  v.reserve(in.total_size() ? size_t(count) : size_t(std::min<uint64_t>(count, 1 << 16)));
}

}  // namespace

PmReader::PmReader(std::istream& in, std::string name, Input input)
    : in_(std::make_unique<ByteReader>(in, std::move(name))) {
  if (input == Input::kPartialStream) in_->forget_size();
  read_header();
}

PmReader::~PmReader() = default;

uint64_t PmReader::offset() const { return in_->offset(); }

bool PmReader::at_end() { return in_->at_end(); }

std::optional<uint64_t> PmReader::stream_size() const { return in_->total_size(); }

void PmReader::read_header() {
  ByteReader& in = *in_;
  PmHeader& h = header_;
  in.set_context("header");
  char magic[8];
  in.bytes(magic, sizeof magic);
  if (!std::equal(magic, magic + 8, fmt::kMagic))
    in.fail_at(0, "not a ParaPM progressive mesh (bad magic)");
  h.version = in.u32();
  if (h.version != fmt::kVersion)
    in.fail_at(fmt::kOffsetVersion, "unsupported .pm format version " + str(h.version) +
                                        " (this build reads version " + str(fmt::kVersion) + ")");
  const uint32_t flags = in.u32();
  if (flags & ~fmt::kKnownFlags)
    in.fail_at(
        fmt::kOffsetFlags, "unknown flags 0x" + [&] {
          char hex[16];
          std::snprintf(hex, sizeof hex, "%x", flags & ~fmt::kKnownFlags);
          return std::string(hex);
        }());
  h.positions_float64 = flags & fmt::kFlagPositionsFloat64;
  h.layout.normals = flags & fmt::kFlagNormals;
  h.layout.texcoords = flags & fmt::kFlagTexcoords;
  h.layout.colors = flags & fmt::kFlagColors;
  const bool has_copies = flags & fmt::kFlagVertexCopies;
  h.has_input_vertex_order = flags & fmt::kFlagInputVertexOrder;
  h.has_input_face_order = flags & fmt::kFlagInputFaceOrder;

  h.base_vertices = in.u32();
  h.base_faces = in.u32();
  h.base_wedges = in.u32();
  h.splits = in.u32();
  h.full_vertices = in.u32();
  h.full_faces = in.u32();
  h.full_wedges = in.u32();
  h.vertex_copies = in.u32();
  h.input_vertices = in.u64();
  h.input_faces = in.u64();
  for (double& c : h.box.min) c = in.f64();
  for (double& c : h.box.max) c = in.f64();
  const uint32_t metric_length = in.u32();
  if (metric_length > fmt::kMaxMetricLength)
    in.fail_at(fmt::kOffsetMetricLength, "metric name of " + str(metric_length) +
                                             " bytes (at most " + str(fmt::kMaxMetricLength) + ")");
  h.metric.resize(metric_length);
  in.bytes(h.metric.data(), metric_length);
  h.size = in.offset();

  // The counts must agree with each other...
  const uint64_t counts = fmt::kOffsetCounts;
  const uint64_t splits = h.splits;
  if (uint64_t(h.base_vertices) + splits != h.full_vertices || h.full_vertices == kNoId)
    in.fail_at(counts, "full vertex count " + str(h.full_vertices) + " is not base vertices " +
                           str(h.base_vertices) + " + splits " + str(splits));
  if (h.full_faces < uint64_t(h.base_faces) + splits ||
      h.full_faces > uint64_t(h.base_faces) + 2 * splits)
    in.fail_at(counts, "full face count " + str(h.full_faces) + " is impossible for " +
                           str(h.base_faces) + " base faces and " + str(splits) + " splits");
  const bool attributes = h.layout.any();
  if (!attributes && (h.base_wedges != 0 || h.full_wedges != 0))
    in.fail_at(counts, "wedges declared without attribute channels");
  if (attributes &&
      (h.full_wedges < h.base_wedges || h.full_wedges > uint64_t(h.base_wedges) + 6 * splits))
    in.fail_at(counts, "full wedge count " + str(h.full_wedges) + " is impossible for " +
                           str(h.base_wedges) + " base wedges and " + str(splits) + " splits");
  if (h.vertex_copies > h.full_vertices || has_copies != (h.vertex_copies != 0))
    in.fail_at(counts, "vertex copy count " + str(h.vertex_copies) + " disagrees with the flags");
  for (int k = 0; k < 3; ++k)
    if (!std::isfinite(h.box.min[k]) || !std::isfinite(h.box.max[k]) || h.box.min[k] > h.box.max[k])
      in.fail_at(fmt::kOffsetBox, "invalid bounding box");

  // ... and with the size of the file, before anything is allocated from them.
  const uint64_t fpw = uint64_t(h.layout.floats_per_wedge());
  const uint64_t coordinate = h.positions_float64 ? 8 : 4;
  uint64_t needed = uint64_t(h.base_vertices) * 3 * coordinate + uint64_t(h.base_faces) * 12 + 4;
  if (attributes) needed += uint64_t(h.base_faces) * 12 + uint64_t(h.base_wedges) * (4 + 4 * fpw);
  needed += splits * (attributes ? fmt::kMinSplitBytesWithAttributes : fmt::kMinSplitBytes);
  needed += uint64_t(h.vertex_copies) * 8 + 4;
  if (h.has_input_vertex_order) needed += uint64_t(h.full_vertices) * 4;
  if (h.has_input_face_order) needed += uint64_t(h.full_faces) * 4;
  if (const auto left = in.remaining(); left && needed > *left)
    in.fail_at(counts, "the header's counts need at least " + str(needed) +
                           " more bytes but the file has " + str(*left));
}

Mesh PmReader::read_base() {
  if (base_read_) throw_internal("PmReader::read_base called twice");
  base_read_ = true;
  ByteReader& in = *in_;
  const PmHeader& h = header_;
  const size_t fpw = size_t(h.layout.floats_per_wedge());
  Mesh base;
  base.layout = h.layout;
  base.positions_are_float = !h.positions_float64;

  in.set_context("base mesh positions");
  reserve_declared(base.positions, h.base_vertices, in);
  for (uint32_t v = 0; v < h.base_vertices; ++v) {
    Vec3 p;
    for (double& c : p) c = h.positions_float64 ? in.f64() : double(in.f32());
    for (double c : p)
      if (!std::isfinite(c)) in.fail("vertex " + str(v) + " has a non-finite coordinate");
    base.positions.push_back(p);
  }
  in.set_context("base mesh faces");
  reserve_declared(base.faces, h.base_faces, in);
  for (uint32_t f = 0; f < h.base_faces; ++f) {
    Triangle t;
    for (VertexId& v : t) {
      v = in.u32();
      if (v >= h.base_vertices)
        in.fail("face " + str(f) + " names vertex " + str(v) + " of " + str(h.base_vertices));
    }
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) in.fail("face " + str(f) + " is degenerate");
    base.faces.push_back(t);
  }
  if (h.layout.any()) {
    in.set_context("base mesh corner wedges");
    reserve_declared(base.face_wedges, h.base_faces, in);
    for (uint32_t f = 0; f < h.base_faces; ++f) {
      std::array<WedgeId, 3> corners;
      for (WedgeId& w : corners) {
        w = in.u32();
        if (w >= h.base_wedges)
          in.fail("face " + str(f) + " names wedge " + str(w) + " of " + str(h.base_wedges));
      }
      base.face_wedges.push_back(corners);
    }
    in.set_context("base mesh wedges");
    reserve_declared(base.wedge_vertex, h.base_wedges, in);
    reserve_declared(base.wedge_values, uint64_t(h.base_wedges) * fpw, in);
    for (uint32_t w = 0; w < h.base_wedges; ++w) {
      const VertexId v = in.u32();
      if (v >= h.base_vertices)
        in.fail("wedge " + str(w) + " belongs to vertex " + str(v) + " of " + str(h.base_vertices));
      base.wedge_vertex.push_back(v);
      for (size_t k = 0; k < fpw; ++k) base.wedge_values.push_back(in.f32());
    }
  }
  in.set_context("header checksum");
  const uint64_t crc_offset = in.offset();
  const uint32_t computed = in.crc();
  if (in.u32() != computed) in.fail_at(crc_offset, "checksum mismatch in the header or base mesh");
  in.reset_crc();

  positions_ = base.positions;
  reserve_declared(positions_, h.full_vertices, in);
  wedge_values_ = base.wedge_values;
  changed_in_.assign(h.base_wedges, 0);
  wedges_ = h.base_wedges;
  faces_ = h.base_faces;
  return base;
}

bool PmReader::next_split(PmSplitRecord& record) {
  if (!base_read_) throw_internal("PmReader::next_split before read_base");
  if (splits_read_ == header_.splits) return false;
  ByteReader& in = *in_;
  const PmHeader& h = header_;
  const size_t i = splits_read_;
  in.set_context("vsplit", i);
  const uint64_t start = in.offset();
  const uint64_t n = uint64_t(h.base_vertices) + i;
  const bool attributes = h.layout.any();
  const size_t fpw = size_t(h.layout.floats_per_wedge());

  VertexSplit& s = record.split;
  s = VertexSplit{};
  record.new_wedge_values.clear();
  record.wedge_changes.clear();
  record.wedge_change_values.clear();

  s.vs = in.varint32();
  if (s.vs >= n) in.fail_at(start, "vs " + str(s.vs) + " out of range (" + str(n) + " vertices)");
  const uint32_t vl_code = in.varint32();
  const uint32_t vr_code = in.varint32();
  s.vl = vl_code == 0 ? kNoId : vl_code - 1;
  s.vr = vr_code == 0 ? kNoId : vr_code - 1;
  if (s.vl != kNoId && s.vl >= n)
    in.fail_at(start, "vl " + str(s.vl) + " out of range (" + str(n) + " vertices)");
  if (s.vr != kNoId && s.vr >= n)
    in.fail_at(start, "vr " + str(s.vr) + " out of range (" + str(n) + " vertices)");
  if (s.vl == kNoId && s.vr == kNoId) in.fail_at(start, "neither vl nor vr");
  if (s.vl == s.vr || s.vl == s.vs || s.vr == s.vs)
    in.fail_at(start, "vs, vl and vr are not distinct");
  const uint64_t error_offset = in.offset();
  s.error = in.f32();
  if (!std::isfinite(s.error) || s.error < 0)
    in.fail_at(error_offset, "error is not a finite non-negative number");
  if (i > 0 && s.error > previous_error_)
    in.fail_at(error_offset, "error exceeds the previous split's (errors must not increase)");

  s.vs_before = positions_[s.vs];
  const uint64_t positions_offset = in.offset();
  for (Vec3* after : {&s.vs_after, &s.vt_after}) {
    for (int k = 0; k < 3; ++k) {
      (*after)[k] = h.positions_float64
                        ? double_apply_delta(s.vs_before[k], in.zigzag64())
                        : double(float_apply_delta(float(s.vs_before[k]), in.zigzag32()));
      if (!std::isfinite((*after)[k])) in.fail_at(positions_offset, "non-finite position");
    }
  }

  if (attributes) {
    uint64_t next_new = wedges_;
    for (int k = 0; k < 6; ++k) {
      if (!(k < 3 ? s.vl != kNoId : s.vr != kNoId)) continue;
      const uint64_t code_offset = in.offset();
      const uint32_t code = in.varint32();
      if (code == 0) {
        s.corner_wedges[k] = WedgeId(next_new++);
        for (size_t j = 0; j < fpw; ++j) record.new_wedge_values.push_back(in.f32());
      } else if (code - 1 < next_new) {
        s.corner_wedges[k] = code - 1;
      } else {
        in.fail_at(code_offset,
                   "corner " + str(k) + " names wedge " + str(code - 1) + " of " + str(next_new));
      }
    }
    s.new_wedge_count = uint32_t(next_new - wedges_);
    if (next_new > h.full_wedges)
      in.fail_at(start, "more wedges than the header's " + str(h.full_wedges));

    const uint64_t count_offset = in.offset();
    const uint32_t changes = in.varint32();
    if (changes > wedges_)
      in.fail_at(count_offset, str(changes) + " wedge changes but only " + str(wedges_) +
                                   " wedges existed before the split");
    in.check_fits(changes, 1 + fpw, "wedge changes");
    for (uint32_t c = 0; c < changes; ++c) {
      const uint64_t change_offset = in.offset();
      const uint32_t w = in.varint32();
      if (w >= wedges_)
        in.fail_at(change_offset, "wedge change names wedge " + str(w) + " of " + str(wedges_));
      if (changed_in_[w] == i + 1)
        in.fail_at(change_offset, "wedge " + str(w) + " is changed twice");
      changed_in_[w] = uint32_t(i + 1);
      record.wedge_changes.push_back({w, uint32_t(record.wedge_change_values.size())});
      float* current = wedge_values_.data() + size_t(w) * fpw;
      record.wedge_change_values.insert(record.wedge_change_values.end(), current, current + fpw);
      for (size_t j = 0; j < fpw; ++j) {
        current[j] = float_apply_delta(current[j], in.zigzag32());
        record.wedge_change_values.push_back(current[j]);
      }
    }
    s.wedge_changes_count = changes;
    wedge_values_.insert(wedge_values_.end(), record.new_wedge_values.begin(),
                         record.new_wedge_values.end());
    changed_in_.resize(next_new, 0);
    wedges_ = next_new;
  }

  positions_[s.vs] = s.vs_after;
  positions_.push_back(s.vt_after);
  faces_ += uint64_t(s.new_faces());
  if (faces_ > h.full_faces) in.fail_at(start, "more faces than the header's " + str(h.full_faces));
  previous_error_ = s.error;
  ++splits_read_;
  return true;
}

PmTail PmReader::read_tail() {
  if (!base_read_ || splits_read_ != header_.splits)
    throw_internal("PmReader::read_tail before the last split");
  ByteReader& in = *in_;
  const PmHeader& h = header_;
  PmTail tail;
  in.set_context("tail");
  if (faces_ != h.full_faces)
    in.fail("the splits create " + str(faces_) + " faces in all, the header says " +
            str(h.full_faces));
  if (wedges_ != h.full_wedges)
    in.fail("the splits create " + str(wedges_) + " wedges in all, the header says " +
            str(h.full_wedges));

  in.set_context("vertex copies");
  reserve_declared(tail.vertex_copies, h.vertex_copies, in);
  for (uint32_t c = 0; c < h.vertex_copies; ++c) {
    const VertexId copy = in.u32();
    const VertexId original = in.u32();
    if (copy >= h.full_vertices || original >= h.full_vertices)
      in.fail("copy " + str(c) + " names a vertex out of range (" + str(h.full_vertices) + ")");
    tail.vertex_copies.emplace_back(copy, original);
  }
  if (h.has_input_vertex_order) {
    in.set_context("input vertex order");
    reserve_declared(tail.input_vertex_order, h.full_vertices, in);
    for (uint32_t v = 0; v < h.full_vertices; ++v) tail.input_vertex_order.push_back(in.u32());
  }
  if (h.has_input_face_order) {
    in.set_context("input face order");
    reserve_declared(tail.input_face_order, h.full_faces, in);
    for (uint32_t f = 0; f < h.full_faces; ++f) tail.input_face_order.push_back(in.u32());
  }
  in.set_context("final checksum");
  const uint64_t crc_offset = in.offset();
  const uint32_t computed = in.crc();
  if (in.u32() != computed) in.fail_at(crc_offset, "checksum mismatch in the splits or the tail");
  if (!in.at_end()) in.fail("unexpected bytes after the end of the progressive mesh");
  return tail;
}

void append_split(ProgressiveMesh& pm, const PmSplitRecord& record) {
  VertexSplit s = record.split;
  s.wedge_changes_begin = uint32_t(pm.wedge_changes.size());
  const uint32_t values_base = uint32_t(pm.wedge_change_values.size());
  for (WedgeChange change : record.wedge_changes) {
    change.values_offset += values_base;
    pm.wedge_changes.push_back(change);
  }
  pm.wedge_change_values.insert(pm.wedge_change_values.end(), record.wedge_change_values.begin(),
                                record.wedge_change_values.end());
  pm.new_wedge_values.insert(pm.new_wedge_values.end(), record.new_wedge_values.begin(),
                             record.new_wedge_values.end());
  pm.splits.push_back(s);
}

ProgressiveMesh read_pm(std::istream& stream, const std::string& name) {
  PmReader reader(stream, name);
  const PmHeader& h = reader.header();
  ProgressiveMesh pm;
  pm.base = reader.read_base();
  pm.info.metric = h.metric;
  pm.info.input_vertices = h.input_vertices;
  pm.info.input_faces = h.input_faces;
  // With a known size the header's counts were checked against it (each record takes at
  // least kMinSplitBytes); with an unknown size the vectors grow as records arrive.
  const std::optional<uint64_t> total = reader.stream_size();
  pm.splits.reserve(total ? size_t(std::min<uint64_t>(h.splits, *total / fmt::kMinSplitBytes))
                          : size_t(std::min<uint64_t>(h.splits, 4096)));
  PmSplitRecord record;
  while (reader.next_split(record)) append_split(pm, record);
  PmTail tail = reader.read_tail();
  pm.vertex_copies = std::move(tail.vertex_copies);
  pm.input_vertex_order = std::move(tail.input_vertex_order);
  pm.input_face_order = std::move(tail.input_face_order);

  try {
    validate_pm(pm);
  } catch (const Error& e) {
    throw_invalid(name + ": " + e.what());
  }
  const Box box = pm_bounding_box(pm);
  for (int k = 0; k < 3; ++k)
    if (std::bit_cast<uint64_t>(box.min[k]) != std::bit_cast<uint64_t>(h.box.min[k]) ||
        std::bit_cast<uint64_t>(box.max[k]) != std::bit_cast<uint64_t>(h.box.max[k]))
      throw_invalid(name + ": byte " + std::to_string(fmt::kOffsetBox) +
                    " (header): the bounding box does not match the positions");
  return pm;
}

}  // namespace parapm
