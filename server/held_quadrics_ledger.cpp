#include "held_quadrics_ledger.h"

#include <algorithm>
#include <tuple>

#include "parallel/held_quadrics.h"
#include "util/job_pool.h"

namespace parapm::service {

void HeldQuadricsLedger::holders(const SubsetJob& job, std::vector<uint32_t>& holder,
                                 std::vector<size_t>& count) const {
  const QuadricState& state = job.state.quadric;
  holder.assign(state.vertices.size(), 0);
  count.assign(workers_.size() + 1, 0);
  if (job.state.metric != "quadric") return;
  for (size_t k = 0; k < state.vertices.size(); ++k) {
    const VertexId local = state.vertices[k];
    if (local >= job.global_vertex.size()) continue;
    const VertexId v = job.global_vertex[local];
    if (v >= holder_.size() || holder_[v] == 0) continue;
    if (fingerprint_[v] != quadric_fingerprint(state.quadrics[k])) continue;
    holder[k] = holder_[v];
    ++count[holder_[v]];
  }
}

std::vector<HeldQuadricsLedger::Plan> HeldQuadricsLedger::plan_round(
    const std::vector<SubsetJob>& jobs, const std::map<std::string, uint32_t>& slots) const {
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

uint32_t HeldQuadricsLedger::index_of(const std::string& worker) {
  const auto it = std::find(workers_.begin(), workers_.end(), worker);
  if (it != workers_.end()) return uint32_t(it - workers_.begin()) + 1;
  workers_.push_back(worker);
  return uint32_t(workers_.size());
}

void HeldQuadricsLedger::record(const std::string& worker,
                                const std::vector<std::pair<VertexId, uint64_t>>& kept) {
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
