// Where the tests find their meshes: the small real meshes committed under tests/data, and
// every mesh of ../shared/meshes when that folder is present (it is in CI).
#pragma once

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace parapm::testing {

inline std::string test_data(const std::string& name) {
  return std::string(PARAPM_TEST_DATA_DIR) + "/" + name;
}

inline std::filesystem::path shared_meshes_dir() {
  if (const char* env = std::getenv("PARAPM_SHARED_MESHES")) return env;
  return PARAPM_SHARED_MESHES_DIR;
}

// Every mesh file of ../shared/meshes, sorted by name; empty when the folder is absent.
inline std::vector<std::filesystem::path> shared_meshes() {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  const auto dir = shared_meshes_dir();
  if (!std::filesystem::is_directory(dir, ec)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name == "README.md" || name == "INVENTORY.tsv" || !entry.is_regular_file()) continue;
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace parapm::testing
