// Writes an 8-bit RGB image as PNG (zlib's deflate and crc32; no other dependency).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace parapm {

// `rgb` holds width x height pixels, row by row from the top, 3 bytes each. Throws
// Error(kIo) when the file cannot be written.
void write_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

}  // namespace parapm
