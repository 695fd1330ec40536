// parapm-render, the benchmark report's picture tool, as a user runs it: a real mesh in, a
// PNG out that decodes (signature, header, zlib stream, CRCs) to the asked size with the
// mesh's colours drawn on a white background.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "test_support.h"

namespace parapm {
namespace {

namespace fs = std::filesystem;

uint32_t read_u32(const std::string& s, size_t at) {
  return (uint32_t(uint8_t(s[at])) << 24) | (uint32_t(uint8_t(s[at + 1])) << 16) |
         (uint32_t(uint8_t(s[at + 2])) << 8) | uint32_t(uint8_t(s[at + 3]));
}

struct Png {
  uint32_t width = 0, height = 0;
  std::string pixels;  // RGB rows, filter bytes removed
};

// Decodes what write_png writes (8-bit RGB, filter 0), checking every chunk's CRC.
Png decode(const std::string& file) {
  Png png;
  EXPECT_EQ(file.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::string idat;
  for (size_t at = 8; at + 12 <= file.size();) {
    const uint32_t length = read_u32(file, at);
    const std::string type = file.substr(at + 4, 4);
    const std::string body = file.substr(at + 4, 4 + length);
    EXPECT_EQ(read_u32(file, at + 8 + length),
              uint32_t(crc32(0, reinterpret_cast<const Bytef*>(body.data()), uInt(body.size()))))
        << type;
    if (type == "IHDR") {
      png.width = read_u32(file, at + 8);
      png.height = read_u32(file, at + 12);
    } else if (type == "IDAT") {
      idat += file.substr(at + 8, length);
    }
    at += 12 + length;
  }
  std::string raw(size_t(png.height) * (size_t(png.width) * 3 + 1), '\0');
  uLongf raw_size = uLongf(raw.size());
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &raw_size,
                       reinterpret_cast<const Bytef*>(idat.data()), uLong(idat.size())),
            Z_OK);
  EXPECT_EQ(raw_size, raw.size());
  for (uint32_t y = 0; y < png.height; ++y)
    png.pixels += raw.substr(size_t(y) * (size_t(png.width) * 3 + 1) + 1, size_t(png.width) * 3);
  return png;
}

TEST(Render, DrawsTheColouredAirplaneTwiceSideBySide) {
  const fs::path out =
      fs::temp_directory_path() / ("parapm-render-" + std::to_string(::getpid()) + ".png");
  const std::string mesh = testing::test_data("pymeshlab-colored-airplane-11k.ply");
  const std::string command = std::string(PARAPM_BINARY_DIR) + "/parapm-render " + mesh + " " +
                              mesh + " -o " + out.string() + " --size 96 > /dev/null";
  ASSERT_EQ(std::system(command.c_str()), 0);
  std::ifstream in(out, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), {});
  fs::remove(out);
  const Png png = decode(file);
  ASSERT_EQ(png.width, 192u);
  ASSERT_EQ(png.height, 96u);
  ASSERT_EQ(png.pixels.size(), size_t(192) * 96 * 3);
  // The two tiles draw the same mesh from the same camera: the same pixels.
  size_t drawn = 0, blue = 0, red = 0;
  for (uint32_t y = 0; y < 96; ++y)
    for (uint32_t x = 0; x < 96; ++x) {
      const size_t left = (size_t(y) * 192 + x) * 3, right = left + 96 * 3;
      ASSERT_EQ(png.pixels.substr(left, 3), png.pixels.substr(right, 3)) << x << ", " << y;
      const auto r = uint8_t(png.pixels[left]), g = uint8_t(png.pixels[left + 1]),
                 b = uint8_t(png.pixels[left + 2]);
      if (r == 255 && g == 255 && b == 255) continue;
      ++drawn;
      if (b > r + 60) ++blue;  // the wing tips' colour
      if (r > b + 60) ++red;   // the nose's
    }
  EXPECT_GT(drawn, 96u * 96u / 20) << "the mesh fills a fair part of its tile";
  EXPECT_GT(blue, 20u);
  EXPECT_GT(red, 20u);
}

TEST(Render, AMissingMeshIsAClearError) {
  const std::string command = std::string(PARAPM_BINARY_DIR) +
                              "/parapm-render /nonexistent/mesh.ply -o /dev/null 2>/dev/null";
  const int status = std::system(command.c_str());
  EXPECT_EQ(WEXITSTATUS(status), 2);
}

}  // namespace
}  // namespace parapm
