// Writing a finished file: optionally gzip-compressed, written beside the target and renamed
// into place so that a reader never sees half a file.
#pragma once

#include <string>
#include <string_view>

namespace parapm::io {

// Compresses to the gzip format (one member), zlib's default level.
std::string gzip_compress(std::string_view bytes);

// Writes `bytes` to `path` (through `path`.tmp and a rename). kIo on failure.
void write_file_bytes(const std::string& path, std::string_view bytes);

}  // namespace parapm::io
