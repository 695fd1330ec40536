// Little-endian binary encoding for the .pm format: fixed-size numbers, LEB128 varints and
// zigzag signed varints, with byte offsets and a running CRC-32 (zlib's) on both sides.
//
// ByteReader is written for untrusted input: every read checks that the bytes exist, every
// failure is an Error(kInvalidInput) "<name>: byte <offset> (<context>): <what>", and the
// total size of a seekable stream is known up front so that callers can refuse counts that
// cannot fit before they allocate anything. A non-seekable stream (a network stream) has no
// known size; callers then grow their buffers as data actually arrives.
#pragma once

#include <cstdint>
#include <istream>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace parapm {

class ByteWriter {
 public:
  // `out` may be null: the writer then only counts bytes (and computes the CRC). Nothing
  // reaches `out` before flush() except full buffers (64 KiB, less at most the 9 bytes a
  // number needed that did not fit).
  explicit ByteWriter(std::ostream* out);
  ~ByteWriter();
  ByteWriter(const ByteWriter&) = delete;
  ByteWriter& operator=(const ByteWriter&) = delete;

  void u8(uint8_t v) {
    room(1);
    buffer_[used_++] = char(v);
  }
  void u32(uint32_t v) {
    room(4);
    for (int k = 0; k < 4; ++k) buffer_[used_++] = char(v >> (8 * k));
  }
  void u64(uint64_t v) {
    room(8);
    for (int k = 0; k < 8; ++k) buffer_[used_++] = char(v >> (8 * k));
  }
  void f32(float v);
  void f64(double v);
  void varint(uint64_t v) {
    room(10);
    while (v >= 0x80) {
      buffer_[used_++] = char(v | 0x80);
      v >>= 7;
    }
    buffer_[used_++] = char(v);
  }
  void zigzag32(int32_t v) { varint((uint32_t(v) << 1) ^ uint32_t(v >> 31)); }
  void zigzag64(int64_t v) { varint((uint64_t(v) << 1) ^ uint64_t(v >> 63)); }
  void bytes(const void* data, size_t size);
  // The same bytes, whose CRC-32 the caller has (another writer's crc() over exactly them):
  // the running CRC is combined with it, not computed over them again.
  void bytes_with_crc(const void* data, size_t size, uint32_t crc);

  uint64_t offset() const { return flushed_ + used_; }
  // CRC-32 of the bytes written since construction or the last reset_crc().
  uint32_t crc();
  void reset_crc();
  // Writes out the buffer; throws Error(kIo) when the stream failed.
  void flush();

  static size_t varint_size(uint64_t v);

 private:
  static constexpr size_t kBufferSize = 1 << 16;
  // Flushes the buffer unless it has room for n more bytes.
  void room(size_t n) {
    if (kBufferSize - used_ < n) flush_buffer();
  }
  void update_crc();
  void flush_buffer();

  std::ostream* out_;
  std::unique_ptr<char[]> buffer_;
  size_t used_ = 0;      // bytes in buffer_
  size_t crc_done_ = 0;  // buffer_ bytes already in crc_
  uint64_t flushed_ = 0;
  unsigned long crc_;
};

class ByteReader {
 public:
  ByteReader(std::istream& in, std::string name);
  ByteReader(const ByteReader&) = delete;
  ByteReader& operator=(const ByteReader&) = delete;

  // Bytes from the reader's start to the end of the stream, when the stream is seekable.
  std::optional<uint64_t> total_size() const { return total_size_; }
  // Treat the stream as one of unknown size (it may be cut short on purpose).
  void forget_size() { total_size_.reset(); }
  uint64_t offset() const { return consumed_ + pos_; }
  // Bytes left, when known.
  std::optional<uint64_t> remaining() const {
    if (!total_size_) return std::nullopt;
    return *total_size_ - offset();
  }
  // Throws unless `count` elements of at least `min_bytes` bytes each can still follow (when
  // the size is known); `what` names them in the message.
  void check_fits(uint64_t count, uint64_t min_bytes, const char* what) const;

  // What is being read, for messages: "vsplit 12", "base mesh faces".
  void set_context(const char* section, uint64_t index = kNoIndex) {
    section_ = section;
    index_ = index;
  }

  uint8_t u8() {
    if (pos_ == end_ && !refill()) truncated();
    return uint8_t(buffer_[pos_++]);
  }
  uint32_t u32();
  uint64_t u64();
  float f32();
  double f64();
  uint32_t varint32();
  uint64_t varint64();
  int32_t zigzag32() {
    const uint32_t z = varint32();
    return int32_t((z >> 1) ^ (~(z & 1) + 1));
  }
  int64_t zigzag64() {
    const uint64_t z = varint64();
    return int64_t((z >> 1) ^ (~(z & 1) + 1));
  }
  void bytes(void* data, size_t size);

  // True when the stream has no more bytes.
  bool at_end();
  // CRC-32 of the bytes read since construction or the last reset_crc().
  uint32_t crc();
  void reset_crc();

  [[noreturn]] void fail(const std::string& what) const { fail_at(offset(), what); }
  [[noreturn]] void fail_at(uint64_t offset, const std::string& what) const;
  const std::string& name() const { return name_; }

  static constexpr uint64_t kNoIndex = ~uint64_t(0);

 private:
  static constexpr size_t kBufferSize = 1 << 16;
  bool refill();
  [[noreturn]] void truncated() const;
  void update_crc();

  std::istream& in_;
  std::string name_;
  std::vector<char> buffer_;
  size_t pos_ = 0;
  size_t end_ = 0;
  size_t crc_done_ = 0;
  uint64_t consumed_ = 0;  // bytes before buffer_[0]
  std::optional<uint64_t> total_size_;
  unsigned long crc_;
  const char* section_ = "header";
  uint64_t index_ = kNoIndex;
};

}  // namespace parapm
