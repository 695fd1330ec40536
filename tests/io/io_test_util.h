// Helpers for the reader and writer tests: reading text written in the test, expecting an
// error with a given code and message, building binary files byte by byte, comparing meshes
// corner by corner, and a temporary folder.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <string>

#include "io/mesh_io.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm::testing {

inline Mesh read_text(const std::string& bytes, const std::string& name,
                      ReadReport* report = nullptr, const ReadLimits& limits = {}) {
  return read_mesh_from_memory(bytes, name, report, limits);
}

// Builds binary data in either byte order.
class Bytes {
 public:
  explicit Bytes(bool big_endian = false) : big_(big_endian) {}
  Bytes& text(const std::string& s) {
    data_ += s;
    return *this;
  }
  template <class T>
  Bytes& put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    const bool swap = big_ != (std::endian::native == std::endian::big);
    if (swap)
      for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
    data_.append(raw, sizeof(T));
    return *this;
  }
  const std::string& str() const { return data_; }
  size_t size() const { return data_.size(); }

 private:
  bool big_;
  std::string data_;
};

inline bool same_bits(double a, double b) {
  return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b);
}
inline bool same_bits(float a, float b) {
  return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b);
}

// Same triangles at every corner: positions bit for bit and, when `attributes`, the same
// attribute values (the vertex and wedge numbering may differ).
inline void expect_same_corners(const Mesh& a, const Mesh& b, bool attributes = true) {
  ASSERT_EQ(a.face_count(), b.face_count());
  if (attributes) {
    ASSERT_EQ(a.layout, b.layout);
  }
  const int stride = a.layout.floats_per_wedge();
  size_t bad = 0;
  for (size_t f = 0; f < a.face_count() && bad < 5; ++f) {
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = a.positions[a.faces[f][k]];
      const Vec3& q = b.positions[b.faces[f][k]];
      bool same = true;
      for (int c = 0; c < 3; ++c) same = same && same_bits(p[c], q[c]);
      if (attributes && a.layout.any()) {
        const float* wa = a.wedge(a.face_wedges[f][k]);
        const float* wb = b.wedge(b.face_wedges[f][k]);
        for (int c = 0; c < stride; ++c) same = same && same_bits(wa[c], wb[c]);
      }
      if (!same) {
        ADD_FAILURE() << "face " << f << " corner " << k << " differs";
        ++bad;
      }
    }
  }
}

// Same vertices (bit for bit), same faces, same wedges.
inline void expect_identical(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.vertex_count(), b.vertex_count());
  for (size_t v = 0; v < a.vertex_count(); ++v)
    for (int c = 0; c < 3; ++c)
      ASSERT_TRUE(same_bits(a.positions[v][c], b.positions[v][c])) << "vertex " << v;
  ASSERT_EQ(a.faces, b.faces);
  ASSERT_EQ(a.layout, b.layout);
  ASSERT_EQ(a.wedge_vertex, b.wedge_vertex);
  ASSERT_EQ(a.face_wedges, b.face_wedges);
  ASSERT_EQ(a.wedge_values.size(), b.wedge_values.size());
  for (size_t i = 0; i < a.wedge_values.size(); ++i)
    ASSERT_TRUE(same_bits(a.wedge_values[i], b.wedge_values[i])) << "wedge value " << i;
  EXPECT_EQ(a.positions_are_float, b.positions_are_float);
}

// A folder under the system temp folder, removed with its content at the end of the test.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("parapm_io_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace parapm::testing
