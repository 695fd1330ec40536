// The finished Progressive Meshes the coordinator serves, read from their blobs on first use
// (or put as the coordinator wrote them) and kept (the most recently used, within a budget of
// the memory they hold: file and decoded PM) for downloads, levels and streams:
// the file's bytes as stored (checked against their hash when read: a corrupt blob is never
// served), the PM decoded from them (validated), and where each split record starts, so that
// StreamPM sends byte ranges of the file as they are.
#pragma once

#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "pm/progressive_mesh.h"
#include "storage/blob_store.h"
#include "util/chunked_loops.h"

namespace parapm::service {

struct LoadedPm {
  std::string bytes;  // the .pm file, its SHA-256 checked
  ProgressiveMesh pm;
  uint64_t splits_begin = 0;          // bytes of header + base mesh (+ its CRC)
  std::vector<uint64_t> split_begin;  // per split, its offset; then the offset after the last
};

// `pm` written as a .pm file, kept with its bytes and the writer's split offsets: what the
// coordinator stores as a blob and puts in the library (validate_pm first: kInvalidInput).
// The splits are encoded in `loops`' chunks (the same bytes on any).
std::shared_ptr<LoadedPm> written_pm(ProgressiveMesh pm, ChunkedLoops& loops);
std::shared_ptr<LoadedPm> written_pm(ProgressiveMesh pm);

class PmLibrary {
 public:
  // Keeps PMs whose memory (file bytes, decoded PM, offsets) adds up to at most `budget_bytes`
  // (always the last one used).
  explicit PmLibrary(uint64_t budget_bytes = uint64_t(512) << 20) : budget_bytes_(budget_bytes) {}
  // Thread-safe; loads outside the lock, so a slow load does not hold up other PMs. Throws
  // Error(kDataLoss) when the blob no longer matches its hash or does not decode (its message
  // names the blob, not a path), kNotFound when it is missing.
  std::shared_ptr<const LoadedPm> get(const std::string& sha256, const BlobStore& blobs);
  // A PM the coordinator has just written, with the bytes it stored under `sha256`: served
  // from memory without reading them back (its first download need not wait for a load).
  void put(const std::string& sha256, std::shared_ptr<const LoadedPm> pm);

 private:
  void keep(const std::string& sha256, std::shared_ptr<const LoadedPm> pm);  // mutex_ held

  uint64_t budget_bytes_;
  std::mutex mutex_;
  std::list<std::pair<std::string, std::shared_ptr<const LoadedPm>>> recent_;  // front: newest
};

}  // namespace parapm::service
