#include "worker_registry.h"

#include <spdlog/spdlog.h>

#include "storage/ids.h"

namespace parapm::service {

WorkerRegistry::WorkerRegistry(std::chrono::milliseconds heartbeat,
                               unsigned missed_beats_until_dead)
    : heartbeat_(heartbeat), missed_beats_(missed_beats_until_dead) {}

void WorkerRegistry::expire() {
  const auto now = std::chrono::steady_clock::now();
  for (auto it = workers_.begin(); it != workers_.end();) {
    if (now - it->second.last_beat > heartbeat_ * missed_beats_) {
      spdlog::warn("worker {} ({}) missed {} beats: dead", it->first, it->second.description.name,
                   missed_beats_);
      it = workers_.erase(it);
    } else {
      ++it;
    }
  }
}

std::string WorkerRegistry::add(const WorkerDescription& worker) {
  std::lock_guard lock(mutex_);
  for (auto it = workers_.begin(); it != workers_.end();) {
    if (it->second.description.address == worker.address) {
      spdlog::info("worker {} at {} registered again: replacing it", it->first, worker.address);
      it = workers_.erase(it);
    } else {
      ++it;
    }
  }
  const std::string id = new_id("worker-");
  Entry entry;
  entry.description = worker;
  entry.description.threads = std::max(1u, worker.threads);
  if (!(entry.description.capacity > 0)) entry.description.capacity = 1;
  entry.last_beat = std::chrono::steady_clock::now();
  workers_[id] = entry;
  spdlog::info("worker {} registered: {} at {}, {} slots, capacity {}", id, worker.name,
               worker.address, entry.description.threads, entry.description.capacity);
  return id;
}

bool WorkerRegistry::beat(const std::string& worker_id, uint32_t running_subsets) {
  std::lock_guard lock(mutex_);
  expire();
  const auto it = workers_.find(worker_id);
  if (it == workers_.end()) return false;
  it->second.last_beat = std::chrono::steady_clock::now();
  it->second.suspected = false;
  spdlog::trace("worker {} beat, {} subsets running", worker_id, running_subsets);
  return true;
}

bool WorkerRegistry::alive(const std::string& worker_id) {
  std::lock_guard lock(mutex_);
  expire();
  return workers_.count(worker_id) != 0;
}

size_t WorkerRegistry::live_count() {
  std::lock_guard lock(mutex_);
  expire();
  return workers_.size();
}

std::map<std::string, uint32_t> WorkerRegistry::live_slots_by_worker() {
  std::lock_guard lock(mutex_);
  expire();
  std::map<std::string, uint32_t> slots;
  for (const auto& [id, entry] : workers_)
    if (!entry.suspected) slots[id] = entry.description.threads;
  return slots;
}

size_t WorkerRegistry::live_slots() {
  std::lock_guard lock(mutex_);
  expire();
  size_t slots = 0;
  for (const auto& [id, entry] : workers_) slots += entry.description.threads;
  return slots;
}

std::optional<WorkerSlot> WorkerRegistry::acquire(const std::set<std::string>& avoid,
                                                  bool queue_ahead) {
  std::lock_guard lock(mutex_);
  expire();
  Entry* best = nullptr;
  std::string best_id;
  double best_load = 0;
  for (auto& [id, entry] : workers_) {
    const uint32_t calls = entry.description.threads * (queue_ahead ? 2 : 1);
    if (entry.suspected || entry.busy >= calls || avoid.count(id)) continue;
    const double load = double(entry.busy + 1) / entry.description.capacity;
    if (!best || load < best_load) {
      best = &entry;
      best_id = id;
      best_load = load;
    }
  }
  if (!best) return std::nullopt;
  ++best->busy;
  return WorkerSlot{best_id, best->description.address, best->description.name};
}

std::optional<WorkerSlot> WorkerRegistry::acquire_on(const std::string& worker_id,
                                                     bool queue_ahead) {
  std::lock_guard lock(mutex_);
  expire();
  const auto it = workers_.find(worker_id);
  if (it == workers_.end()) return std::nullopt;
  Entry& entry = it->second;
  if (entry.suspected || entry.busy >= entry.description.threads * (queue_ahead ? 2 : 1))
    return std::nullopt;
  ++entry.busy;
  return WorkerSlot{worker_id, entry.description.address, entry.description.name};
}

void WorkerRegistry::release(const std::string& worker_id) {
  std::lock_guard lock(mutex_);
  const auto it = workers_.find(worker_id);
  if (it != workers_.end() && it->second.busy > 0) --it->second.busy;
}

void WorkerRegistry::suspect(const std::string& worker_id) {
  std::lock_guard lock(mutex_);
  const auto it = workers_.find(worker_id);
  if (it != workers_.end()) it->second.suspected = true;
}

}  // namespace parapm::service
