#include "held_quadrics_cache.h"

#include <spdlog/spdlog.h>

namespace parapm::worker {

HeldQuadricsCache::HeldQuadricsCache(uint64_t max_bytes, std::chrono::seconds idle)
    : max_bytes_(max_bytes), idle_(idle) {}

bool HeldQuadricsCache::find(const std::string& build, const std::vector<VertexId>& vertices,
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

void HeldQuadricsCache::keep(const std::string& build, const QuadricState& quadrics) {
  if (build.empty() || quadrics.vertices.empty() || max_bytes_ == 0) return;
  std::lock_guard lock(mutex_);
  Build& held = builds_[build];
  held.last_use = std::chrono::steady_clock::now();
  for (size_t i = 0; i < quadrics.vertices.size(); ++i)
    held.quadrics.insert_or_assign(quadrics.vertices[i], quadrics.quadrics[i]);
  trim(build);
}

uint64_t HeldQuadricsCache::bytes_locked() const {
  uint64_t n = 0;
  for (const auto& [key, build] : builds_) n += build.quadrics.size();
  return n * kEntryBytes;
}

uint64_t HeldQuadricsCache::bytes() const {
  std::lock_guard lock(mutex_);
  return bytes_locked();
}

size_t HeldQuadricsCache::builds() const {
  std::lock_guard lock(mutex_);
  return builds_.size();
}

void HeldQuadricsCache::trim(const std::string& keep_build) {
  const auto now = std::chrono::steady_clock::now();
  for (auto it = builds_.begin(); it != builds_.end();) {
    if (it->first != keep_build && now - it->second.last_use > idle_) {
      spdlog::info("held quadrics of build {} dropped: unused for {} s", it->first, idle_.count());
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
    spdlog::info("held quadrics of build {} dropped: the cache's {} MB are full", oldest->first,
                 max_bytes_ >> 20);
    builds_.erase(oldest);
  }
}

}  // namespace parapm::worker
