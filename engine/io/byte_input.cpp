#include "io/byte_input.h"

#include <libdeflate.h>
#include <sys/stat.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <utility>

#include "util/chunked_loops.h"
#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm::io {
namespace {

struct FileCloser {
  void operator()(FILE* f) const { std::fclose(f); }
};

// zlib counts in 32-bit uInt: feed and drain it in slices no larger than this.
constexpr uint64_t kZlibSlice = uint64_t(1) << 30;

}  // namespace

std::string read_file_bytes(const std::string& path, uint64_t max_bytes, ChunkedLoops* loops) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT || err == ENOTDIR) throw Error(ErrorCode::kNotFound, path + ": no such file");
    throw Error(ErrorCode::kIo, path + ": " + std::strerror(err));
  }
  if (S_ISDIR(st.st_mode)) throw Error(ErrorCode::kIo, path + ": is a directory, not a file");
  std::unique_ptr<FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) {
    const int err = errno;
    throw Error(err == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIo,
                path + ": cannot open: " + std::strerror(err));
  }
  const uint64_t size = st.st_size > 0 ? uint64_t(st.st_size) : 0;
  if (size > max_bytes)
    throw Error(ErrorCode::kResourceExhausted, path + ": the file has " + std::to_string(size) +
                                                   " bytes, more than the limit of " +
                                                   std::to_string(max_bytes));
  std::string bytes;
  ChunkedLoops one_thread;
  resize_touched(bytes, size, loops ? *loops : one_thread);
  size_t got = size ? std::fread(bytes.data(), 1, size, file.get()) : 0;
  if (got != size) {
    if (std::ferror(file.get()))
      throw Error(ErrorCode::kIo, path + ": read failed: " + std::strerror(errno));
    bytes.resize(got);  // the file shrank while we read it: take what is there
  }
  // Special files report size 0 (pipes, /proc): read them to the end, within the limit.
  if (size == 0) {
    char chunk[1 << 16];
    while ((got = std::fread(chunk, 1, sizeof chunk, file.get())) > 0) {
      if (bytes.size() + got > max_bytes)
        throw Error(ErrorCode::kResourceExhausted,
                    path + ": more than the limit of " + std::to_string(max_bytes) + " bytes");
      bytes.append(chunk, got);
    }
    if (std::ferror(file.get()))
      throw Error(ErrorCode::kIo, path + ": read failed: " + std::strerror(errno));
  }
  return bytes;
}

bool is_gzip(std::string_view bytes) {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

// The size the gzip trailer declares (ISIZE: the last member's size mod 2^32): a hint for the
// output buffer once the start has been checked, never trusted beyond `cap`.
uint64_t declared_size(std::string_view compressed) {
  if (compressed.size() < 18) return 0;
  const auto* tail =
      reinterpret_cast<const unsigned char*>(compressed.data() + compressed.size() - 4);
  return uint64_t(tail[0]) | uint64_t(tail[1]) << 8 | uint64_t(tail[2]) << 16 |
         uint64_t(tail[3]) << 24;
}

// Inflates with zlib's stream, member after member, checking the limit as the output grows:
// the reference path, and the one that names the offset of what is wrong.
std::string gunzip_stream(std::string_view compressed, const std::string& name, uint64_t max_bytes,
                          const StartCheck& check_start) {
  z_stream zs{};
  // 15 + 16: gzip wrapper only (zlib or raw deflate data is not accepted as .gz).
  if (inflateInit2(&zs, 15 + 16) != Z_OK)
    throw Error(ErrorCode::kInternal, name + ": zlib inflateInit2 failed");
  struct Ender {
    z_stream* zs;
    ~Ender() { inflateEnd(zs); }
  } ender{&zs};

  // Capacity may reach max_bytes + 1: one byte beyond the limit proves the limit was passed.
  const uint64_t cap = max_bytes + 1;
  std::string out;
  // The first buffer holds just the start to check; it grows only after the check passed.
  out.resize(size_t(std::min<uint64_t>(cap, kStartCheckBytes)));
  bool start_checked = !check_start;
  auto check_once = [&](uint64_t out_pos) {
    if (start_checked) return;
    start_checked = true;
    check_start(std::string_view(out.data(), size_t(out_pos)));
  };
  uint64_t in_pos = 0, out_pos = 0;
  for (;;) {
    if (zs.avail_in == 0 && in_pos < compressed.size()) {
      zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data() + in_pos));
      zs.avail_in = uInt(std::min<uint64_t>(kZlibSlice, compressed.size() - in_pos));
      in_pos += zs.avail_in;
    }
    if (out_pos == out.size()) {
      check_once(out_pos);
      if (out.size() >= cap)
        throw Error(ErrorCode::kResourceExhausted, name +
                                                       ": decompresses to more than the limit of " +
                                                       std::to_string(max_bytes) + " bytes");
      const uint64_t hint = std::max<uint64_t>(declared_size(compressed), out.size() * 2);
      out.resize(
          size_t(std::min<uint64_t>(cap, out.size() == kStartCheckBytes ? hint : out.size() * 2)));
    }
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + out_pos);
    zs.avail_out = uInt(std::min<uint64_t>(kZlibSlice, out.size() - out_pos));
    const uInt avail_before = zs.avail_out;
    const int rc = inflate(&zs, Z_NO_FLUSH);
    out_pos += avail_before - zs.avail_out;
    if (out_pos > max_bytes)
      throw Error(ErrorCode::kResourceExhausted, name +
                                                     ": decompresses to more than the limit of " +
                                                     std::to_string(max_bytes) + " bytes");
    const uint64_t consumed = in_pos - zs.avail_in;
    if (rc == Z_STREAM_END) {
      // Another member may follow (gzip concatenation); anything else after the end is garbage.
      if (consumed == compressed.size()) break;
      if (!is_gzip(compressed.substr(consumed)))
        throw Error(ErrorCode::kInvalidInput,
                    name + ": compressed byte " + std::to_string(consumed) +
                        ": data after the end of the gzip stream is not another gzip member");
      inflateReset(&zs);
      continue;
    }
    if (rc == Z_BUF_ERROR) {
      // No progress possible: the output is full (grow it), the input slice is used up (feed
      // the next one), or the input ran out before the stream ended.
      if (zs.avail_out == 0) continue;
      if (zs.avail_in == 0 && in_pos < compressed.size()) continue;
      throw Error(ErrorCode::kInvalidInput,
                  name + ": compressed byte " + std::to_string(consumed) +
                      ": the gzip data is truncated (the stream does not end)");
    }
    if (rc != Z_OK) {
      throw Error(ErrorCode::kInvalidInput,
                  name + ": compressed byte " + std::to_string(consumed) + ": corrupt gzip data" +
                      (zs.msg ? std::string(" (") + zs.msg + ")" : std::string()));
    }
    if (zs.avail_in == 0 && in_pos == compressed.size() && zs.avail_out != 0)
      throw Error(ErrorCode::kInvalidInput,
                  name + ": compressed byte " + std::to_string(consumed) +
                      ": the gzip data is truncated (the stream does not end)");
  }
  out.resize(size_t(out_pos));
  check_once(out_pos);
  return out;
}

// The first kStartCheckBytes inflated bytes, or the whole output when the only member ends
// before them; empty when zlib's stream would give the check something else (the data is
// corrupt or cut short there, or another member follows), which gunzip_stream then decides.
std::optional<std::string> inflated_start(std::string_view compressed) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 16) != Z_OK) return std::nullopt;
  std::string start(size_t(kStartCheckBytes), '\0');
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  zs.avail_in = uInt(std::min<uint64_t>(kZlibSlice, compressed.size()));
  zs.next_out = reinterpret_cast<Bytef*>(start.data());
  zs.avail_out = uInt(start.size());
  const int rc = inflate(&zs, Z_SYNC_FLUSH);
  const bool whole = rc == Z_STREAM_END && zs.avail_in == 0 && compressed.size() <= kZlibSlice;
  const bool full = (rc == Z_OK || rc == Z_BUF_ERROR) && zs.avail_out == 0;
  start.resize(start.size() - zs.avail_out);
  inflateEnd(&zs);
  if (!whole && !full) return std::nullopt;
  return start;
}

// libdeflate in one call, into a buffer of the size the trailer declares: about three times
// as fast as zlib's stream. Empty when it does not apply: a declared size above the limit,
// several members, data that does not inflate to exactly the declared size, corrupt data.
std::optional<std::string> gunzip_whole(std::string_view compressed, uint64_t max_bytes,
                                        ChunkedLoops* loops) {
  const uint64_t declared = declared_size(compressed);
  if (compressed.size() < 18 || declared > max_bytes) return std::nullopt;
  std::string out;
  ChunkedLoops one_thread;
  resize_touched(out, size_t(declared), loops ? *loops : one_thread);
  libdeflate_decompressor* decompressor = libdeflate_alloc_decompressor();
  if (!decompressor) return std::nullopt;
  size_t in_bytes = 0, out_bytes = 0;
  const libdeflate_result rc =
      libdeflate_gzip_decompress_ex(decompressor, compressed.data(), compressed.size(), out.data(),
                                    out.size(), &in_bytes, &out_bytes);
  libdeflate_free_decompressor(decompressor);
  if (rc != LIBDEFLATE_SUCCESS || in_bytes != compressed.size() || out_bytes != out.size())
    return std::nullopt;
  return out;
}

std::string gunzip(std::string_view compressed, const std::string& name, uint64_t max_bytes,
                   const StartCheck& check_start, ChunkedLoops* loops) {
  if (max_bytes < kStartCheckBytes) return gunzip_stream(compressed, name, max_bytes, check_start);
  if (check_start) {
    const std::optional<std::string> start = inflated_start(compressed);
    if (!start) return gunzip_stream(compressed, name, max_bytes, check_start);
    check_start(*start);
  }
  // (moved out: the inflated bytes are the read's largest block)
  if (std::optional<std::string> whole = gunzip_whole(compressed, max_bytes, loops))
    return std::move(*whole);
  return gunzip_stream(compressed, name, max_bytes, {});
}

}  // namespace parapm::io
