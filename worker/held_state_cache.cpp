#include "held_state_cache.h"

#include <algorithm>

#include <spdlog/spdlog.h>

namespace parapm::worker {

HeldStateCache::HeldStateCache(uint64_t max_bytes, std::chrono::seconds idle)
    : max_bytes_(max_bytes), idle_(idle) {}

uint64_t HeldStateCache::Build::bytes() const {
  return quadrics.size() * kQuadricBytes + have.size() * (kPointBytes + 4 * k);
}

bool HeldStateCache::find(const std::string& build, const std::vector<VertexId>& vertices,
                          std::vector<Quadric>& out) {
  std::lock_guard lock(mutex_);
  trim(build);
  const auto it = builds_.find(build);
  if (it == builds_.end()) return vertices.empty();
  it->second.last_use = std::chrono::steady_clock::now();
  out.clear();
  out.reserve(vertices.size());
  for (VertexId v : vertices) {
    const auto q = it->second.quadrics.find(v);
    if (q == it->second.quadrics.end()) return false;
    out.push_back(q->second);
  }
  return true;
}

void HeldStateCache::keep(const std::string& build, const QuadricState& quadrics) {
  if (build.empty() || quadrics.vertices.empty() || max_bytes_ == 0) return;
  std::lock_guard lock(mutex_);
  Build& held = builds_[build];
  held.last_use = std::chrono::steady_clock::now();
  for (size_t i = 0; i < quadrics.vertices.size(); ++i)
    held.quadrics.insert_or_assign(quadrics.vertices[i], quadrics.quadrics[i]);
  trim(build);
}

bool HeldStateCache::find_points(const std::string& build, const std::vector<uint32_t>& ids,
                                 size_t k, std::vector<HeldPoint>& points,
                                 std::vector<float>& values) {
  std::lock_guard lock(mutex_);
  trim(build);
  const auto it = builds_.find(build);
  if (it == builds_.end()) return ids.empty();
  Build& held = it->second;
  held.last_use = std::chrono::steady_clock::now();
  if (!ids.empty() && held.k != k) return false;
  points.clear();
  values.clear();
  points.reserve(ids.size());
  values.reserve(ids.size() * k);
  for (uint32_t id : ids) {
    if (id >= held.have.size() || !held.have[id]) return false;
    points.push_back(held.points[id]);
    values.insert(values.end(), held.values.begin() + ptrdiff_t(id * k),
                  held.values.begin() + ptrdiff_t((id + 1) * k));
  }
  return true;
}

void HeldStateCache::keep_points(const std::string& build, const EnergyState& state) {
  if (build.empty() || state.points.empty() || !state.positions || max_bytes_ == 0) return;
  const size_t k = state.point_values.size() / state.points.size();
  uint32_t largest = 0;
  for (const EnergyState::Point& p : state.points) largest = std::max(largest, p.id);
  std::lock_guard lock(mutex_);
  Build& held = builds_[build];
  held.last_use = std::chrono::steady_clock::now();
  if (held.have.empty()) held.k = k;
  const uint64_t size = uint64_t(largest) + 1;
  if (held.k != k || size * (kPointBytes + 4 * k) > max_bytes_) {
    // Points of another kind, or more than the whole cache could hold: none kept.
    held.points = {};
    held.values = {};
    held.have = {};
  } else {
    if (size > held.have.size()) {
      held.points.resize(size);
      held.values.resize(size * k);
      held.have.resize(size, 0);
    }
    for (size_t i = 0; i < state.points.size(); ++i) {
      const EnergyState::Point& p = state.points[i];
      held.points[p.id] = {p.position, p.distance_sq, p.residual};
      std::copy_n(state.point_values.begin() + ptrdiff_t(i * k), k,
                  held.values.begin() + ptrdiff_t(size_t(p.id) * k));
      held.have[p.id] = 1;
    }
  }
  trim(build);
}

void HeldStateCache::update_points(const std::string& build, const EnergyState& returned) {
  if (build.empty() || returned.points.empty()) return;
  std::lock_guard lock(mutex_);
  const auto it = builds_.find(build);
  if (it == builds_.end()) return;
  Build& held = it->second;
  for (const EnergyState::Point& p : returned.points) {
    if (p.id >= held.have.size() || !held.have[p.id]) continue;
    held.points[p.id].distance_sq = p.distance_sq;
    held.points[p.id].residual = p.residual;
  }
}

uint64_t HeldStateCache::bytes_locked() const {
  uint64_t n = 0;
  for (const auto& [key, build] : builds_) n += build.bytes();
  return n;
}

uint64_t HeldStateCache::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_locked();
}

size_t HeldStateCache::builds() const {
  std::lock_guard lock(mutex_);
  return builds_.size();
}

size_t HeldStateCache::item_bound(const std::string& build) const {
  std::lock_guard lock(mutex_);
  const auto it = builds_.find(build);
  return it == builds_.end() ? 0 : it->second.quadrics.size() + it->second.points.size();
}

void HeldStateCache::trim(const std::string& keep_build) {
  const auto now = std::chrono::steady_clock::now();
  for (auto it = builds_.begin(); it != builds_.end();) {
    if (it->first != keep_build && now - it->second.last_use > idle_) {
      spdlog::info("held state of build {} dropped: unused for {} s", it->first, idle_.count());
      it = builds_.erase(it);
    } else {
      ++it;
    }
  }
  while (!builds_.empty() && bytes_locked() > max_bytes_) {
    auto oldest = builds_.end();
    for (auto it = builds_.begin(); it != builds_.end(); ++it)
      if (it->first != keep_build &&
          (oldest == builds_.end() || it->second.last_use < oldest->second.last_use))
        oldest = it;
    if (oldest == builds_.end()) oldest = builds_.find(keep_build);
    spdlog::info("held state of build {} dropped: the cache's {} MB are full", oldest->first,
                 max_bytes_ >> 20);
    builds_.erase(oldest);
  }
}

}  // namespace parapm::worker
