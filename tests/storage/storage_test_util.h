// Helpers for the storage tests: a fresh temporary folder per test, and a check that a call
// throws parapm::Error with a given code and message.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>

#include "storage/ids.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm::testing {

// A new, empty folder under the system temp folder, removed with everything in it when the
// test ends.
class TempDir {
 public:
  TempDir()
      : path_(std::filesystem::temp_directory_path() / service::new_id("parapm-storage-test-")) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot open " << path;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_file(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

}  // namespace parapm::testing
