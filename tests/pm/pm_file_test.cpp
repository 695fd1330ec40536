// The .pm file: bit-identical round trips, the streaming reader, and corrupt input (every
// truncation, every flipped byte, hostile header counts) rejected with an Error.
#include "pm/pm_file.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <streambuf>

#include <unistd.h>
#include <zlib.h>

#include "pm/byte_io.h"
#include "pm/pm_format.h"
#include "pm/pm_restore.h"
#include "pm_fixtures.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

std::string encode(const ProgressiveMesh& pm) {
  std::ostringstream out(std::ios::binary);
  write_pm(pm, out);
  return out.str();
}

ProgressiveMesh decode(const std::string& bytes) {
  std::istringstream in(bytes, std::ios::binary);
  return read_pm(in, "test.pm");
}

// A PM with everything the format carries: attributes, new wedges, wedge changes, copies
// (vertex 5 ends where vertex 4 is), input orders.
ProgressiveMesh everything_pm() {
  ProgressiveMesh pm = testing::strip_pm();
  pm.splits[0].vt_after = {2, 2, 0};
  pm.vertex_copies = {{5, 4}};
  pm.info = {"quadric", 9, 7, 0.125};
  pm.input_vertex_order = {8, 1, 2, 3, 4, 4, 0};
  pm.input_face_order = {6, 5, 4, 3, 2, 1};
  return pm;
}

void expect_same_pm(const ProgressiveMesh& a, const ProgressiveMesh& b) {
  auto bits = [](const Vec3& p) {
    return std::array<uint64_t, 3>{std::bit_cast<uint64_t>(p[0]), std::bit_cast<uint64_t>(p[1]),
                                   std::bit_cast<uint64_t>(p[2])};
  };
  ASSERT_EQ(a.base.vertex_count(), b.base.vertex_count());
  for (size_t v = 0; v < a.base.vertex_count(); ++v)
    EXPECT_EQ(bits(a.base.positions[v]), bits(b.base.positions[v]));
  EXPECT_EQ(a.base.faces, b.base.faces);
  EXPECT_EQ(a.base.layout, b.base.layout);
  EXPECT_EQ(a.base.wedge_vertex, b.base.wedge_vertex);
  EXPECT_EQ(a.base.face_wedges, b.base.face_wedges);
  EXPECT_EQ(a.base.positions_are_float, b.base.positions_are_float);
  ASSERT_EQ(a.splits.size(), b.splits.size());
  for (size_t i = 0; i < a.splits.size(); ++i) {
    const VertexSplit &s = a.splits[i], &t = b.splits[i];
    EXPECT_EQ(s.vs, t.vs);
    EXPECT_EQ(s.vl, t.vl);
    EXPECT_EQ(s.vr, t.vr);
    EXPECT_EQ(std::bit_cast<uint32_t>(s.error), std::bit_cast<uint32_t>(t.error));
    EXPECT_EQ(bits(s.vs_before), bits(t.vs_before));
    EXPECT_EQ(bits(s.vs_after), bits(t.vs_after));
    EXPECT_EQ(bits(s.vt_after), bits(t.vt_after));
    EXPECT_EQ(s.corner_wedges, t.corner_wedges);
    EXPECT_EQ(s.new_wedge_count, t.new_wedge_count);
    EXPECT_EQ(s.wedge_changes_begin, t.wedge_changes_begin);
    EXPECT_EQ(s.wedge_changes_count, t.wedge_changes_count);
  }
  auto float_bits = [](const std::vector<float>& v) {
    std::vector<uint32_t> out;
    for (float x : v) out.push_back(std::bit_cast<uint32_t>(x));
    return out;
  };
  EXPECT_EQ(float_bits(a.base.wedge_values), float_bits(b.base.wedge_values));
  EXPECT_EQ(float_bits(a.new_wedge_values), float_bits(b.new_wedge_values));
  EXPECT_EQ(float_bits(a.wedge_change_values), float_bits(b.wedge_change_values));
  ASSERT_EQ(a.wedge_changes.size(), b.wedge_changes.size());
  for (size_t c = 0; c < a.wedge_changes.size(); ++c) {
    EXPECT_EQ(a.wedge_changes[c].wedge, b.wedge_changes[c].wedge);
    EXPECT_EQ(a.wedge_changes[c].values_offset, b.wedge_changes[c].values_offset);
  }
  EXPECT_EQ(a.vertex_copies, b.vertex_copies);
  EXPECT_EQ(a.input_vertex_order, b.input_vertex_order);
  EXPECT_EQ(a.input_face_order, b.input_face_order);
  EXPECT_EQ(a.info.metric, b.info.metric);
  EXPECT_EQ(a.info.input_vertices, b.info.input_vertices);
  EXPECT_EQ(a.info.input_faces, b.info.input_faces);
}

std::vector<ProgressiveMesh> round_trip_pms() {
  std::vector<ProgressiveMesh> pms = {ProgressiveMesh{},
                                      testing::strip_pm(),
                                      testing::octahedron_pm(false),
                                      testing::octahedron_pm(true),
                                      testing::cut_fan_pm(),
                                      everything_pm()};
  for (bool closed : {true, false})
    for (bool attributes : {false, true})
      for (bool float32 : {true, false})
        pms.push_back(testing::random_pm(500, {closed, attributes, float32, 99}));
  return pms;
}

TEST(PmFile, RoundTripIsBitIdentical) {
  for (const ProgressiveMesh& pm : round_trip_pms()) {
    const std::string first = encode(pm);
    EXPECT_EQ(pm_encoded_size(pm), first.size());
    const ProgressiveMesh read = decode(first);
    expect_same_pm(pm, read);
    EXPECT_EQ(encode(read), first);
  }
}

// The offsets write_pm reports are the reader's, split by split: a server serves byte ranges
// of a PM it wrote at them without reading it back.
TEST(PmFile, TheWritersSplitOffsetsAreTheReaders) {
  for (const ProgressiveMesh& pm : round_trip_pms()) {
    std::ostringstream out;
    std::vector<uint64_t> written = {7};  // replaced, not appended to
    write_pm(pm, out, &written);
    const std::string bytes = out.str();
    EXPECT_EQ(bytes, encode(pm));
    std::istringstream in(bytes);
    PmReader reader(in);
    reader.read_base();
    std::vector<uint64_t> read = {reader.offset()};
    PmSplitRecord record;
    while (reader.next_split(record)) read.push_back(reader.offset());
    EXPECT_EQ(written, read);
    EXPECT_EQ(written.size(), pm.splits.size() + 1);
  }
}

// Written in chunks side by side (a parallel build's process), the splits make the same bytes
// and the same offsets, the bounding box is the same: every PM, cut into ranges as short as one
// split, on two threads, with attributes (new wedges counted from the ranges before) and without.
TEST(PmFile, TheSplitsWrittenInChunksAreTheSameBytes) {
  for (const ProgressiveMesh& pm : round_trip_pms()) {
    std::vector<uint64_t> plain_offsets;
    std::ostringstream plain;
    write_pm(pm, plain, &plain_offsets);
    for (const unsigned chunks : {2u, 7u, 64u}) {
      ChunkedLoops loops(chunks, 2, 1);
      std::vector<uint64_t> chunked_offsets;
      std::ostringstream chunked;
      write_pm(pm, chunked, loops, &chunked_offsets);
      EXPECT_EQ(chunked.str(), plain.str()) << chunks << " chunks, " << pm.splits.size();
      EXPECT_EQ(chunked_offsets, plain_offsets);
      const Box a = pm_bounding_box(pm), b = pm_bounding_box(pm, loops);
      EXPECT_EQ(a.min, b.min);
      EXPECT_EQ(a.max, b.max);
    }
  }
}

// Bytes appended with their CRC known (a chunk's own writer's) are the same bytes and the same
// running CRC as bytes written plainly: short ones through the buffer, long ones past it.
TEST(PmFile, BytesWithTheirCrcKeepTheRunningCrc) {
  for (const size_t size : {size_t(0), size_t(5), size_t(70000), size_t(300000)}) {
    std::string chunk(size, '\0');
    for (size_t i = 0; i < size; ++i) chunk[i] = char(i * 131 + (i >> 9));
    ByteWriter counted(nullptr);
    counted.bytes(chunk.data(), chunk.size());
    const uint32_t chunk_crc = counted.crc();
    std::ostringstream plain_out, combined_out;
    ByteWriter plain(&plain_out), combined(&combined_out);
    for (ByteWriter* w : {&plain, &combined}) w->u32(0xdeadbeef);
    plain.bytes(chunk.data(), chunk.size());
    combined.bytes_with_crc(chunk.data(), chunk.size(), chunk_crc);
    for (ByteWriter* w : {&plain, &combined}) w->varint(300);
    EXPECT_EQ(combined.offset(), plain.offset()) << size;
    EXPECT_EQ(combined.crc(), plain.crc()) << size;
    plain.flush();
    combined.flush();
    EXPECT_EQ(combined_out.str(), plain_out.str()) << size;
  }
}

TEST(PmFile, Float64PositionsSurviveExactly) {
  // Positions no float32 can hold, negative zero, tiny and huge magnitudes.
  ProgressiveMesh pm = testing::strip_pm();
  pm.base.positions_are_float = false;
  pm.base.positions[0] = {0.1, -0.0, 1e-300};
  pm.splits[0].vs_before = pm.base.positions[1] = {1.5 + 1e-12, -7e200, 0};
  pm.splits[0].vs_after = {-1.5, 7e200, -1e-310};
  pm.splits[0].vt_after = {std::nextafter(2.0, 3.0), -0.0, 0.0};
  const std::string bytes = encode(pm);
  const ProgressiveMesh read = decode(bytes);
  expect_same_pm(pm, read);
  EXPECT_EQ(encode(read), bytes);
  // Float32 PMs store 4-byte base coordinates, float64 ones 8-byte.
  const ProgressiveMesh f32 = testing::strip_pm();
  EXPECT_EQ(encode(pm).size() - encode(f32).size() >= 5 * 3 * 4, true);
}

TEST(PmFile, FileFunctions) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("parapm_pm_file_test_" + std::to_string(::getpid()) + ".pm");
  const ProgressiveMesh pm = everything_pm();
  write_pm_file(pm, path.string());
  expect_same_pm(pm, read_pm_file(path.string()));
  std::filesystem::remove(path);
  try {
    read_pm_file(path.string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kNotFound);
  }
  // An invalid PM is refused before the file is created.
  ProgressiveMesh bad = pm;
  bad.splits[0].vs = 99;
  EXPECT_THROW(write_pm_file(bad, path.string()), Error);
  EXPECT_FALSE(std::filesystem::exists(path));
}

// A stream that cannot seek, like a socket: the reader does not know the size.
class UnseekableBuffer : public std::streambuf {
 public:
  explicit UnseekableBuffer(std::string data) : data_(std::move(data)) {
    char* p = data_.data();
    setg(p, p, p + data_.size());
  }

 private:
  std::string data_;
};

TEST(PmFile, StreamingReaderReadsSplitBySplit) {
  const ProgressiveMesh pm = testing::octahedron_pm(true);
  UnseekableBuffer buffer(encode(pm));
  std::istream in(&buffer);
  PmReader reader(in, "stream");
  EXPECT_EQ(reader.header().splits, 3u);
  EXPECT_EQ(reader.header().full_faces, 14u);
  EXPECT_EQ(reader.header().full_wedges, 10u);
  EXPECT_TRUE(reader.header().layout.texcoords);
  EXPECT_FALSE(reader.header().positions_float64);
  EXPECT_EQ(reader.header().box.min, (Vec3{-1, -1, -1}));
  const Mesh base = reader.read_base();
  EXPECT_EQ(base.faces, pm.base.faces);
  PmSplitRecord record;
  for (size_t i = 0; i < 3; ++i) {
    ASSERT_TRUE(reader.next_split(record));
    EXPECT_EQ(record.split.vs, pm.splits[i].vs);
    EXPECT_EQ(record.split.vs_before, pm.splits[i].vs_before);
    EXPECT_EQ(record.split.vt_after, pm.splits[i].vt_after);
    EXPECT_EQ(record.split.corner_wedges, pm.splits[i].corner_wedges);
    EXPECT_EQ(record.wedge_changes.size(), pm.splits[i].wedge_changes_count);
    EXPECT_EQ(reader.splits_read(), i + 1);
  }
  EXPECT_FALSE(reader.next_split(record));
  EXPECT_NO_THROW(reader.read_tail());

  // read_pm on an unseekable stream: same PM.
  UnseekableBuffer again(encode(pm));
  std::istream in2(&again);
  expect_same_pm(pm, read_pm(in2));
}

TEST(PmFile, AStreamMayStopAfterAnySplit) {
  const ProgressiveMesh pm = testing::random_pm(50, {false, true, true, 3});
  const std::string bytes = encode(pm);
  // Half the bytes arrived: a partial stream, whose size says nothing about the counts.
  std::istringstream in(bytes.substr(0, bytes.size() / 2), std::ios::binary);
  PmReader reader(in, "stream", PmReader::Input::kPartialStream);
  reader.read_base();
  PmSplitRecord record;
  size_t read = 0;
  try {
    while (reader.next_split(record)) ++read;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
  EXPECT_GT(read, 0u);
  EXPECT_LT(read, 50u);
  // The positions so far are those of level `read`.
  ProgressiveMesh prefix = pm;
  prefix.splits.resize(read);
  std::vector<Vec3> expected = pm.base.positions;
  for (const VertexSplit& s : prefix.splits) {
    expected[s.vs] = s.vs_after;
    expected.push_back(s.vt_after);
  }
  EXPECT_EQ(reader.positions(), expected);
}

// Expects decoding `bytes` to fail with kInvalidInput, the message containing `fragment`.
void expect_rejected(const std::string& bytes, const std::string& fragment) {
  try {
    decode(bytes);
    ADD_FAILURE() << "accepted; expected '" << fragment << "'";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

void put_u32(std::string& bytes, size_t offset, uint32_t value) {
  for (int k = 0; k < 4; ++k) bytes[offset + k] = char(value >> (8 * k));
}

TEST(PmFile, RejectsEveryTruncation) {
  for (const ProgressiveMesh& pm : {everything_pm(), testing::octahedron_pm(true)}) {
    const std::string bytes = encode(pm);
    for (size_t size = 0; size < bytes.size(); ++size) {
      try {
        decode(bytes.substr(0, size));
        ADD_FAILURE() << "a file cut at byte " << size << " was accepted";
      } catch (const Error& e) {
        ASSERT_EQ(e.code(), ErrorCode::kInvalidInput) << e.what();
      }
    }
    // Streamed without a known size, too.
    for (size_t size = 0; size < bytes.size(); size += 7) {
      UnseekableBuffer buffer(bytes.substr(0, size));
      std::istream in(&buffer);
      EXPECT_THROW(read_pm(in), Error) << size;
    }
    expect_rejected(bytes + "x", "unexpected bytes after the end");
  }
}

TEST(PmFile, RejectsEveryFlippedByte) {
  for (const ProgressiveMesh& pm : {everything_pm(), testing::octahedron_pm(true)}) {
    const std::string bytes = encode(pm);
    for (size_t offset = 0; offset < bytes.size(); ++offset)
      for (uint8_t mask : {uint8_t(0x01), uint8_t(0x80), uint8_t(0xff)}) {
        std::string corrupt = bytes;
        corrupt[offset] = char(corrupt[offset] ^ mask);
        try {
          decode(corrupt);
          ADD_FAILURE() << "byte " << offset << " ^ " << int(mask) << " was accepted";
        } catch (const Error& e) {
          ASSERT_EQ(e.code(), ErrorCode::kInvalidInput) << e.what();
        }
      }
  }
}

TEST(PmFile, HeaderErrorsSayWhatAndWhere) {
  const std::string bytes = encode(everything_pm());
  std::string bad = bytes;
  bad[0] = 'P';
  expect_rejected(bad, "byte 0 (header): not a ParaPM progressive mesh (bad magic)");
  bad = bytes;
  put_u32(bad, pm_format::kOffsetVersion, 2);
  expect_rejected(bad, "byte 8 (header): unsupported .pm format version 2");
  bad = bytes;
  put_u32(bad, pm_format::kOffsetFlags, 1u << 9);
  expect_rejected(bad, "unknown flags 0x200");
  expect_rejected(std::string(), "truncated");
  expect_rejected(bytes.substr(0, 20), "byte 20 (header): truncated");
}

TEST(PmFile, HostileCountsAreRefusedBeforeAllocating) {
  const std::string bytes = encode(testing::octahedron_pm(true));
  const size_t counts = pm_format::kOffsetCounts;
  // 2 billion splits, consistent with each other: only the file size can refuse them.
  std::string bad = bytes;
  put_u32(bad, counts + 12, 0x7ffffff0u);       // splits
  put_u32(bad, counts + 16, 0x7ffffff0u + 6);   // full vertices
  put_u32(bad, counts + 20, 0x7ffffff0u + 20);  // full faces (>= base + splits)
  expect_rejected(bad, "more bytes but the file has");
  // A base mesh of 2^32 - 2 vertices.
  bad = bytes;
  put_u32(bad, counts + 0, 0xfffffffeu);
  expect_rejected(bad, "full vertex count");
  bad = bytes;
  put_u32(bad, counts + 0, 0x40000000u);
  put_u32(bad, counts + 16, 0x40000003u);
  expect_rejected(bad, "the header's counts need at least");
  // Inconsistent counts.
  bad = bytes;
  put_u32(bad, counts + 20, 99);
  expect_rejected(bad, "full face count 99 is impossible");
  bad = bytes;
  put_u32(bad, counts + 28, 3);  // copies without the flag
  expect_rejected(bad, "vertex copy count");
  bad = bytes;
  put_u32(bad, pm_format::kOffsetMetricLength, 100000);
  expect_rejected(bad, "metric name of 100000 bytes");
}

TEST(PmFile, OutOfRangeIdsInARecordAreNamed) {
  const ProgressiveMesh pm = testing::octahedron_pm(false);
  const std::string bytes = encode(pm);
  // The first record follows the header, the base mesh and its checksum.
  const size_t first_split =
      pm_format::kFixedHeaderSize + pm.info.metric.size() + 6 * 12 + 8 * 12 + 4;
  ASSERT_EQ(uint8_t(bytes[first_split]), 4u);  // vs of split 0
  std::string bad = bytes;
  bad[first_split] = 0x7f;
  expect_rejected(bad, "(vsplit 0): vs 127 out of range (6 vertices)");
  bad = bytes;
  bad[first_split + 1] = 0x08;  // vl + 1 = 8
  expect_rejected(bad, "(vsplit 0): vl 7 out of range");
  bad = bytes;
  bad[first_split + 1] = 0x00;
  bad[first_split + 2] = 0x00;
  expect_rejected(bad, "neither vl nor vr");
}

TEST(PmFile, ReadPmValidates) {
  // A well-formed file whose content breaks an invariant only validate_pm() sees: the copy
  // pair in the tail is changed from (5, 4) to (5, 3), a vertex at another position, and the
  // final checksum recomputed so that nothing else is wrong.
  const ProgressiveMesh pm = everything_pm();
  std::string bytes = encode(pm);
  const size_t tail = bytes.size() - 4 - 6 * 4 - 7 * 4 - 8;
  ASSERT_EQ(uint8_t(bytes[tail]), 5u);
  ASSERT_EQ(uint8_t(bytes[tail + 4]), 4u);
  put_u32(bytes, tail + 4, 3);
  const size_t splits_start =
      pm_format::kFixedHeaderSize + pm.info.metric.size() + 5 * 12 + 4 * 12 + 4;
  const uLong crc =
      crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data() + splits_start),
            uInt(bytes.size() - 4 - splits_start));
  put_u32(bytes, bytes.size() - 4, uint32_t(crc));
  expect_rejected(bytes, "not at the position of its original");
}

TEST(PmFile, SizeIsCompact) {
  // A float32 PM without attributes: a 13..25-byte record per split.
  const ProgressiveMesh pm = testing::random_pm(5000, {true, false, true, 4});
  const size_t size = pm_encoded_size(pm);
  const size_t indexed_mesh = pm.full_vertex_count() * 12 + pm.full_face_count() * 12;
  EXPECT_LT(size, indexed_mesh * 3 / 2) << size << " vs plain " << indexed_mesh;
}

}  // namespace
}  // namespace parapm
