// The finished Progressive Meshes the coordinator serves, read from their blobs on first use
// and kept (a few, most recently used) for levels and streams: the PM itself (validated) and
// where each split record starts in the file, so that StreamPM sends byte ranges of the file
// as they are.
#pragma once

#include <filesystem>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "pm/progressive_mesh.h"

namespace parapm::service {

struct LoadedPm {
  std::filesystem::path path;
  ProgressiveMesh pm;
  uint64_t file_size = 0;
  uint64_t splits_begin = 0;          // bytes of header + base mesh (+ its CRC)
  std::vector<uint64_t> split_begin;  // per split, its offset; then the offset after the last
};

class PmLibrary {
 public:
  explicit PmLibrary(size_t capacity = 4) : capacity_(capacity) {}
  // Thread-safe; loads outside the lock, so a slow load does not hold up other PMs.
  std::shared_ptr<const LoadedPm> get(const std::string& sha256, const std::filesystem::path& path);

 private:
  size_t capacity_;
  std::mutex mutex_;
  std::list<std::pair<std::string, std::shared_ptr<const LoadedPm>>> recent_;  // front: newest
};

// Reads the file at `path` byte range [begin, end).
std::string read_file_range(const std::filesystem::path& path, uint64_t begin, uint64_t end);

}  // namespace parapm::service
