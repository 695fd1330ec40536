#include "held_state_ledger.h"

#include <algorithm>
#include <tuple>

#include "util/job_pool.h"

namespace parapm::service {

void HeldStateLedger::holders(const Items& items, std::vector<uint32_t>& holder,
                              std::vector<size_t>& count) const {
  holder.assign(items.size(), 0);
  count.assign(workers_.size() + 1, 0);
  for (size_t k = 0; k < items.size(); ++k) {
    const auto [id, fingerprint] = items[k];
    if (id >= holder_.size() || holder_[id] == 0 || fingerprint_[id] != fingerprint) continue;
    holder[k] = holder_[id];
    ++count[holder_[id]];
  }
}

std::vector<HeldStateLedger::Plan> HeldStateLedger::plan_round(
    const std::vector<Items>& jobs, const std::map<std::string, uint32_t>& slots) const {
  std::vector<Plan> plans(jobs.size());
  if (holder_.empty() || slots.empty()) return plans;
  std::vector<std::vector<uint32_t>> holder(jobs.size());
  std::vector<std::vector<size_t>> count(jobs.size());
  run_jobs(jobs.size(), 0, [&](size_t i) { holders(jobs[i], holder[i], count[i]); });

  // Each live worker's share of the round's jobs, by its slots.
  uint64_t total_slots = 0;
  for (const auto& [id, n] : slots) total_slots += n;
  std::vector<size_t> room(workers_.size() + 1, 0);
  for (uint32_t w = 1; w <= workers_.size(); ++w)
    if (const auto it = slots.find(workers_[w - 1]); it != slots.end())
      room[w] = (jobs.size() * it->second + total_slots - 1) / total_slots;
  // (count, job, worker) pairs, most held first; ties by job, then worker, for a plan that
  // does not depend on the threads.
  std::vector<std::tuple<size_t, size_t, uint32_t>> pairs;
  for (size_t i = 0; i < jobs.size(); ++i)
    for (uint32_t w = 1; w < count[i].size(); ++w)
      if (count[i][w] > 0 && room[w] > 0) pairs.emplace_back(count[i][w], i, w);
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) > std::get<0>(b) : a < b;
  });
  for (const auto& [n, i, w] : pairs) {
    if (!plans[i].worker.empty() || room[w] == 0) continue;
    --room[w];
    Plan& plan = plans[i];
    plan.worker = workers_[w - 1];
    plan.count = n;
    plan.held.resize(holder[i].size());
    for (size_t k = 0; k < holder[i].size(); ++k) plan.held[k] = holder[i][k] == w;
  }
  return plans;
}

uint32_t HeldStateLedger::index_of(const std::string& worker) {
  const auto it = std::find(workers_.begin(), workers_.end(), worker);
  if (it != workers_.end()) return uint32_t(it - workers_.begin()) + 1;
  workers_.push_back(worker);
  return uint32_t(workers_.size());
}

void HeldStateLedger::record(const std::string& worker,
                             const std::vector<std::pair<uint32_t, uint64_t>>& kept) {
  const uint32_t w = index_of(worker);
  for (const auto& [v, fingerprint] : kept) {
    if (v >= holder_.size()) {
      holder_.resize(size_t(v) + 1, 0);
      fingerprint_.resize(size_t(v) + 1, 0);
    }
    holder_[v] = w;
    fingerprint_[v] = fingerprint;
  }
}

}  // namespace parapm::service
