// The quadrics a worker keeps between a build's rounds (engine/parallel/held_quadrics.h): per
// build, by global vertex id, each the value the vertex's job of the latest round left it
// with. Bounded: past `max_bytes` the builds used longest ago are dropped whole, and a build
// unused for `idle` is dropped at the next use of the cache; a later job naming a dropped
// quadric is refused (FAILED_PRECONDITION) and comes again whole. Thread-safe.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "simplify/module_state.h"

namespace parapm::worker {

class HeldQuadricsCache {
 public:
  HeldQuadricsCache(uint64_t max_bytes, std::chrono::seconds idle);

  // The quadrics of `vertices` (global ids) kept under `build`, in order; false when any is
  // missing (`out` is then unspecified).
  bool find(const std::string& build, const std::vector<VertexId>& vertices,
            std::vector<Quadric>& out);
  // Keeps `quadrics` (global ids) under `build`, replacing what it held for those vertices.
  void keep(const std::string& build, const QuadricState& quadrics);

  uint64_t bytes() const;
  size_t builds() const;

  // What one kept quadric costs, with its key and the hash table's share.
  static constexpr uint64_t kEntryBytes = 128;

 private:
  struct Build {
    std::unordered_map<VertexId, Quadric> quadrics;
    std::chrono::steady_clock::time_point last_use;
  };
  // Drops idle builds, then the longest unused ones (but `keep_build`) while over the bound;
  // `keep_build` itself last. Caller holds mutex_.
  void trim(const std::string& keep_build);
  uint64_t bytes_locked() const;

  uint64_t max_bytes_;
  std::chrono::seconds idle_;
  mutable std::mutex mutex_;
  std::map<std::string, Build> builds_;
};

}  // namespace parapm::worker
