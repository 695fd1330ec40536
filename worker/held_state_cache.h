// The state a worker keeps between a build's rounds (engine/parallel/held_state.h), per build:
// quadrics by global vertex id (each the value the vertex's job of the latest round left it
// with) and the energy's sample points by point id: their positions and attribute values
// (they never change), distances and residuals (as the point's latest job left them). Bounded: past
// `max_bytes` the builds used longest ago are dropped whole, and a build unused for `idle` is
// dropped at the next use of the cache; a later job naming what was dropped is refused
// (FAILED_PRECONDITION) and comes again whole. Thread-safe.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "parallel/held_state.h"
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

  // The points `ids` kept under `build` and their values (k floats each), in order; false
  // when any is missing or was kept with another k.
  bool find_points(const std::string& build, const std::vector<uint32_t>& ids, size_t k,
                   std::vector<HeldPoint>& points, std::vector<float>& values);
  // Keeps an energy state's points (a job's: with positions).
  void keep_points(const std::string& build, const EnergyState& state);
  // Takes the distances and residuals of a job's returned state's points (without positions)
  // into the points kept under `build`.
  void update_points(const std::string& build, const EnergyState& returned);

  uint64_t bytes() const;
  size_t builds() const;
  // At least as many as the items `build` holds (its quadrics, and its points' ids up to the
  // largest): a job naming more held items than that is refused before it is decoded.
  size_t item_bound(const std::string& build) const;

  // What one kept quadric costs, with its key and the hash table's share; a kept point its
  // position, distance, residual, flag and 4 bytes per value, for every id up to the largest.
  static constexpr uint64_t kQuadricBytes = 128;
  static constexpr uint64_t kPointBytes = sizeof(HeldPoint) + 1;

 private:
  struct Build {
    std::unordered_map<VertexId, Quadric> quadrics;
    // Points, dense by id (ids are the master's, 0 to its count).
    std::vector<HeldPoint> points;
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
