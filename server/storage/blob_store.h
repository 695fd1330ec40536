// Content-addressed files: a blob is stored once, under the SHA-256 of its bytes, at
// DIR/blobs/<first 2 hex>/<64 hex>. Uploaded meshes and built Progressive Meshes live here;
// the job database refers to them by hash.
//
// Writing is crash-safe: bytes go to a temp file in DIR/blobs/tmp while their hash is computed,
// and commit() fsyncs the file, renames it to its hash name and fsyncs the folder. So a blob
// name either does not exist or names complete, durable bytes. Callers commit a blob before
// they write a database row that refers to it: after a crash a row never points at a missing
// blob (at worst a blob has no row, which costs only disk space).
//
// Reading checks: read() hashes what it read and throws Error(kDataLoss) when the bytes no
// longer hash to the blob's name (a flipped byte, a cut file), so nothing corrupt is used or
// served. Messages thrown name blobs by hash, never by path (they reach clients); the paths go
// to the log.
//
// Thread safety: the const members and begin() may be called from many threads; each Writer
// belongs to one thread. One BlobStore per data folder per process: the constructor removes
// every temp file, which would break another live store's writers.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "storage/sha256.h"

namespace parapm::service {

class BlobStore {
 public:
  // Creates DIR/blobs and DIR/blobs/tmp when absent and removes the temp files a crash left
  // behind. Throws kIo when the folders cannot be made.
  explicit BlobStore(std::filesystem::path data_dir);

  // A streaming put. Not thread-safe; movable. Destroying it without commit() removes its
  // temp file, so an abandoned upload leaves nothing behind.
  class Writer {
   public:
    Writer(Writer&& other) noexcept;
    Writer& operator=(Writer&& other) noexcept;
    ~Writer();

    void write(std::string_view bytes);  // throws kIo on a failed write
    uint64_t size() const { return size_; }
    // fsyncs and renames the temp file to its hash name; when that blob exists already the
    // temp file is dropped instead (same hash, same bytes) and the blob's time set to now. Returns
    // the hex hash. The writer is finished afterwards: write() and commit() throw kInternal.
    std::string commit();

   private:
    friend class BlobStore;
    Writer(const BlobStore& store, std::filesystem::path temp_path, int fd);
    void discard() noexcept;

    const BlobStore* store_ = nullptr;
    std::filesystem::path temp_path_;
    int fd_ = -1;  // -1 once committed, discarded or moved from
    uint64_t size_ = 0;
    Sha256 hash_;
  };

  Writer begin();
  std::string put(std::string_view bytes);  // whole-buffer convenience; returns the hex hash

  // False for a malformed hash (anything but 64 lowercase hex) as well as for a missing blob.
  bool contains(const std::string& sha) const;
  // Where the blob is or would be. Throws kInvalidInput on a malformed hash.
  std::filesystem::path path_of(const std::string& sha) const;
  // Throw kInvalidInput on a malformed hash, kNotFound when the blob is absent, kIo otherwise;
  // read() also kDataLoss when the bytes do not hash to `sha`.
  uint64_t size_of(const std::string& sha) const;
  std::string read(const std::string& sha) const;

  // Every blob stored under DATA_DIR hashed again: the names of those whose bytes no longer
  // match (or cannot be read), in name order. Reads the whole store; touches nothing, so it
  // may run beside a live coordinator.
  struct VerifyReport {
    uint64_t blobs = 0, bytes = 0;
    std::vector<std::string> corrupt;
  };
  static VerifyReport verify(const std::filesystem::path& data_dir);

  // Removes the blobs not in `keep` that are older than `min_age` (by modification time: a
  // blob just committed whose row is not written yet is never taken). Returns what it freed.
  struct Removed {
    uint64_t blobs = 0, bytes = 0;
  };
  Removed remove_unreferenced(const std::set<std::string>& keep,
                              std::chrono::seconds min_age) const;
  uint64_t stored_bytes() const;  // of every blob

  const std::filesystem::path& blobs_dir() const { return blobs_dir_; }
  const std::filesystem::path& temp_dir() const { return temp_dir_; }

 private:
  std::filesystem::path blobs_dir_;
  std::filesystem::path temp_dir_;
};

}  // namespace parapm::service
