// Buffered little-endian reading and writing with offsets and CRC-32 (byte_io.h).
#include "pm/byte_io.h"

#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cstring>

#include "util/error.h"

namespace parapm {

// ---- ByteWriter ---------------------------------------------------------------------------

ByteWriter::ByteWriter(std::ostream* out)
    : out_(out), buffer_(new char[kBufferSize]), crc_(crc32(0L, Z_NULL, 0)) {}

// Bytes not flush()ed are dropped: a writer abandoned by an exception leaves no half record.
ByteWriter::~ByteWriter() = default;

void ByteWriter::f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
void ByteWriter::f64(double v) { u64(std::bit_cast<uint64_t>(v)); }

size_t ByteWriter::varint_size(uint64_t v) {
  size_t size = 1;
  while (v >= 0x80) {
    v >>= 7;
    ++size;
  }
  return size;
}

void ByteWriter::bytes(const void* data, size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    room(1);
    const size_t n = std::min(size, kBufferSize - used_);
    std::memcpy(buffer_.get() + used_, p, n);
    used_ += n;
    p += n;
    size -= n;
  }
}

void ByteWriter::bytes_with_crc(const void* data, size_t size, uint32_t crc) {
  update_crc();
  crc_ = crc32_combine(crc_, crc, z_off_t(size));
  const char* p = static_cast<const char*>(data);
  if (size >= kBufferSize) {  // past the buffer: straight to the stream
    flush_buffer();
    if (out_) out_->write(p, std::streamsize(size));
    flushed_ += size;
    return;
  }
  while (size > 0) {
    room(1);
    const size_t n = std::min(size, kBufferSize - used_);
    std::memcpy(buffer_.get() + used_, p, n);
    used_ += n;
    crc_done_ = used_;
    p += n;
    size -= n;
  }
}

void ByteWriter::update_crc() {
  if (crc_done_ < used_)
    crc_ = crc32(crc_, reinterpret_cast<const Bytef*>(buffer_.get() + crc_done_),
                 uInt(used_ - crc_done_));
  crc_done_ = used_;
}

uint32_t ByteWriter::crc() {
  update_crc();
  return uint32_t(crc_);
}

void ByteWriter::reset_crc() {
  update_crc();
  crc_ = crc32(0L, Z_NULL, 0);
}

void ByteWriter::flush_buffer() {
  update_crc();
  if (out_) out_->write(buffer_.get(), std::streamsize(used_));
  flushed_ += used_;
  used_ = 0;
  crc_done_ = 0;
}

void ByteWriter::flush() {
  flush_buffer();
  if (out_) {
    out_->flush();
    if (!*out_) throw Error(ErrorCode::kIo, "writing the progressive mesh failed");
  }
}

// ---- ByteReader ---------------------------------------------------------------------------

ByteReader::ByteReader(std::istream& in, std::string name)
    : in_(in), name_(std::move(name)), buffer_(kBufferSize), crc_(crc32(0L, Z_NULL, 0)) {
  // A seekable stream tells its size; a pipe or socket does not (tellg() fails).
  const std::istream::pos_type start = in_.tellg();
  if (start != std::istream::pos_type(-1)) {
    in_.seekg(0, std::ios::end);
    const std::istream::pos_type end = in_.tellg();
    in_.seekg(start);
    if (end != std::istream::pos_type(-1) && end >= start && in_)
      total_size_ = uint64_t(end - start);
    in_.clear();
  } else {
    in_.clear();
  }
}

void ByteReader::fail_at(uint64_t offset, const std::string& what) const {
  std::string where = name_ + ": byte " + std::to_string(offset) + " (" + section_;
  if (index_ != kNoIndex) where += " " + std::to_string(index_);
  throw_invalid(where + "): " + what);
}

void ByteReader::truncated() const {
  fail("truncated: the data ends here (" + std::to_string(offset()) + " bytes)");
}

void ByteReader::check_fits(uint64_t count, uint64_t min_bytes, const char* what) const {
  const auto left = remaining();
  if (!left) return;
  // count * min_bytes without overflow.
  if (min_bytes != 0 && count > *left / min_bytes)
    fail(std::string("the header declares ") + std::to_string(count) + " " + what + " (at least " +
         std::to_string(min_bytes) + " bytes each) but only " + std::to_string(*left) +
         " bytes follow");
}

void ByteReader::update_crc() {
  if (crc_done_ < pos_)
    crc_ = crc32(crc_, reinterpret_cast<const Bytef*>(buffer_.data() + crc_done_),
                 uInt(pos_ - crc_done_));
  crc_done_ = pos_;
}

uint32_t ByteReader::crc() {
  update_crc();
  return uint32_t(crc_);
}

void ByteReader::reset_crc() {
  update_crc();
  crc_ = crc32(0L, Z_NULL, 0);
}

bool ByteReader::refill() {
  update_crc();
  // Keep nothing: every byte before pos_ was consumed.
  consumed_ += pos_;
  pos_ = end_ = crc_done_ = 0;
  if (!in_) return false;
  in_.read(buffer_.data(), std::streamsize(buffer_.size()));
  end_ = size_t(in_.gcount());
  if (in_.bad()) throw Error(ErrorCode::kIo, name_ + ": reading failed");
  return end_ > 0;
}

bool ByteReader::at_end() { return pos_ == end_ && !refill(); }

uint32_t ByteReader::u32() {
  uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v |= uint32_t(u8()) << (8 * k);
  return v;
}
uint64_t ByteReader::u64() {
  uint64_t v = 0;
  for (int k = 0; k < 8; ++k) v |= uint64_t(u8()) << (8 * k);
  return v;
}
float ByteReader::f32() { return std::bit_cast<float>(u32()); }
double ByteReader::f64() { return std::bit_cast<double>(u64()); }

uint32_t ByteReader::varint32() {
  const uint64_t start = offset();
  uint32_t v = 0;
  for (int shift = 0; shift < 35; shift += 7) {
    const uint8_t byte = u8();
    if (shift == 28 && byte > 0x0f) fail_at(start, "varint exceeds 32 bits");
    v |= uint32_t(byte & 0x7f) << shift;
    if (!(byte & 0x80)) return v;
  }
  fail_at(start, "varint exceeds 32 bits");
}

uint64_t ByteReader::varint64() {
  const uint64_t start = offset();
  uint64_t v = 0;
  for (int shift = 0; shift < 70; shift += 7) {
    const uint8_t byte = u8();
    if (shift == 63 && byte > 0x01) fail_at(start, "varint exceeds 64 bits");
    v |= uint64_t(byte & 0x7f) << shift;
    if (!(byte & 0x80)) return v;
  }
  fail_at(start, "varint exceeds 64 bits");
}

void ByteReader::bytes(void* data, size_t size) {
  char* p = static_cast<char*>(data);
  while (size > 0) {
    if (pos_ == end_ && !refill()) truncated();
    const size_t n = std::min(size, end_ - pos_);
    std::memcpy(p, buffer_.data() + pos_, n);
    pos_ += n;
    p += n;
    size -= n;
  }
}

}  // namespace parapm
