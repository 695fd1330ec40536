// The state a worker keeps between a build's rounds (engine/parallel/held_state.h), per build:
// quadrics by global vertex id (each the value the vertex's job of the latest round left it
// with) and the energy's sample points' positions and attribute values by point id (they never
// change). Bounded: past `max_bytes` the builds used longest ago are dropped whole, and a build
// unused for `idle` is dropped at the next use of the cache; a later job naming what was
// dropped is refused (FAILED_PRECONDITION) and comes again whole. Thread-safe.
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

class HeldStateCache {
 public:
  HeldStateCache(uint64_t max_bytes, std::chrono::seconds idle);

  // The quadrics of `vertices` (global ids) kept under `build`, in order; false when any is
  // missing (`out` is then unspecified).
  bool find(const std::string& build, const std::vector<VertexId>& vertices,
            std::vector<Quadric>& out);
  // Keeps `quadrics` (global ids) under `build`, replacing what it held for those vertices.
  void keep(const std::string& build, const QuadricState& quadrics);

  // The positions and values (k floats each) of the points `ids` kept under `build`, in
  // order; false when any is missing or was kept with another k.
  bool find_points(const std::string& build, const std::vector<uint32_t>& ids, size_t k,
                   std::vector<Vec3>& positions, std::vector<float>& values);
  // Keeps the positions and values of an energy state's points (a job's: with positions).
  void keep_points(const std::string& build, const EnergyState& state);

  uint64_t bytes() const;
  size_t builds() const;

  // What one kept quadric costs, with its key and the hash table's share; a kept point its
  // position, its flag and 4 bytes per value, for every id up to the largest kept.
  static constexpr uint64_t kQuadricBytes = 128;
  static constexpr uint64_t kPointBytes = 25;

 private:
  struct Build {
    std::unordered_map<VertexId, Quadric> quadrics;
    // Points, dense by id (ids are the master's, 0 to its count).
    std::vector<Vec3> positions;
    std::vector<float> values;  // k per point
    std::vector<uint8_t> have;
    size_t k = 0;
    std::chrono::steady_clock::time_point last_use;
    uint64_t bytes() const;
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
