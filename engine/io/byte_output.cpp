#include "io/byte_output.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "util/error.h"

namespace parapm::io {
namespace {

// zlib counts in 32-bit uInt: feed and drain it in slices no larger than this.
constexpr uint64_t kZlibSlice = uint64_t(1) << 30;

}  // namespace

std::string gzip_compress(std::string_view bytes) {
  z_stream zs{};
  // 15 + 16: gzip wrapper; memLevel 8 is zlib's default.
  if (deflateInit2(&zs, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw Error(ErrorCode::kInternal, "zlib deflateInit2 failed");
  struct Ender {
    z_stream* zs;
    ~Ender() { deflateEnd(zs); }
  } ender{&zs};
  std::string out;
  out.resize(std::max<size_t>(bytes.size() / 3, 1 << 16));
  uint64_t in_pos = 0, out_pos = 0;
  for (;;) {
    if (zs.avail_in == 0 && in_pos < bytes.size()) {
      zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data() + in_pos));
      zs.avail_in = uInt(std::min<uint64_t>(kZlibSlice, bytes.size() - in_pos));
      in_pos += zs.avail_in;
    }
    if (out_pos == out.size()) out.resize(out.size() * 2);
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + out_pos);
    zs.avail_out = uInt(std::min<uint64_t>(kZlibSlice, out.size() - out_pos));
    const uInt avail_before = zs.avail_out;
    const int flush = (in_pos == bytes.size() && zs.avail_in == 0) ? Z_FINISH : Z_NO_FLUSH;
    const int rc = deflate(&zs, flush);
    out_pos += avail_before - zs.avail_out;
    if (rc == Z_STREAM_END) break;
    if (rc != Z_OK && rc != Z_BUF_ERROR) throw Error(ErrorCode::kInternal, "zlib deflate failed");
  }
  out.resize(size_t(out_pos));
  return out;
}

void write_file_bytes(const std::string& path, std::string_view bytes) {
  const std::string tmp = path + ".tmp";
  FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) throw Error(ErrorCode::kIo, path + ": cannot create: " + std::strerror(errno));
  const size_t written = bytes.empty() ? 0 : std::fwrite(bytes.data(), 1, bytes.size(), file);
  const int write_errno = errno;
  const bool closed = std::fclose(file) == 0;
  if (written != bytes.size() || !closed) {
    std::remove(tmp.c_str());
    throw Error(ErrorCode::kIo, path + ": write failed: " +
                                    std::strerror(written != bytes.size() ? write_errno : errno));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    throw Error(ErrorCode::kIo,
                path + ": cannot rename the written file into place: " + std::strerror(err));
  }
}

}  // namespace parapm::io
