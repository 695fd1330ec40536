// Getting the bytes of a mesh file into memory: the whole file at once, then gzip inflated when
// it is gzip. Readers then parse the buffer with pointers, never with streams.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace parapm {
class ChunkedLoops;
}

namespace parapm::io {

// Reads the whole file. kNotFound when it does not exist, kIo when it cannot be read (or is a
// directory), kResourceExhausted when it is larger than max_bytes. With `loops`, the pages of
// the block it is read into are touched in its chunks first (fresh_pages.h).
std::string read_file_bytes(const std::string& path, uint64_t max_bytes,
                            ChunkedLoops* loops = nullptr);

// True when the bytes start with the gzip magic (1f 8b).
bool is_gzip(std::string_view bytes);

// Inflates gzip data, concatenated members too (as `cat a.gz b.gz` or pigz produce). The
// output never grows beyond max_bytes + 1 bytes: passing max_bytes is kResourceExhausted as
// soon as it happens, so a gzip bomb costs at most the limit. Corrupt or truncated data is
// kInvalidInput naming `name` and the compressed byte offset. One member whose trailer
// declares a size within the limit is inflated by libdeflate in one call (about three times
// as fast as zlib's stream); anything else, or a call that fails, by zlib's stream.
//
// `check_start`, when given, is called once with the first kStartCheckBytes inflated bytes
// (fewer when the data is shorter) before more is inflated, and throws to stop there: a file
// that is not a mesh costs only that much, however large it would inflate.
using StartCheck = std::function<void(std::string_view start)>;
constexpr uint64_t kStartCheckBytes = uint64_t(1) << 16;
// With `loops`, the pages of the inflated block are touched in its chunks first (fresh_pages.h).
std::string gunzip(std::string_view compressed, const std::string& name, uint64_t max_bytes,
                   const StartCheck& check_start = {}, ChunkedLoops* loops = nullptr);

}  // namespace parapm::io
