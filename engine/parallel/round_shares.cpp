#include "parallel/round_shares.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <utility>

#include "parallel/simplify_subset.h"
#include "simplify/collapse_mesh.h"
#include "simplify/copy_groups.h"
#include "simplify/simplifier.h"
#include "util/error.h"

namespace parapm {

SampledEdges sampled_edges(const SubsetJob& job, const std::vector<uint8_t>& free) {
  SampledEdges out;
  auto inner = [&](VertexId a, VertexId b) { return a < b && job.owned[a] && job.owned[b]; };
  uint64_t free_edges = 0;
  for (const Triangle& t : job.mesh.faces)
    for (int k = 0; k < 3; ++k) {
      const VertexId a = t[k], b = t[(k + 1) % 3];
      out.inner_edges += inner(a, b) ? 1 : 0;
      free_edges += inner(a, b) && free[a] && free[b] ? 1 : 0;
    }
  if (free_edges == 0) return out;
  const uint64_t stride = std::max<uint64_t>(1, free_edges / kSampledEdgesPerSubset);
  out.edges.reserve(free_edges / stride + 1);
  uint64_t index = 0;
  for (const Triangle& t : job.mesh.faces)
    for (int k = 0; k < 3; ++k) {
      const VertexId a = t[k], b = t[(k + 1) % 3];
      if (inner(a, b) && free[a] && free[b] && index++ % stride == 0) out.edges.push_back({a, b});
    }
  return out;
}

SubsetSample sample_subset(const SubsetJob& job, const std::vector<uint8_t>& free, bool carry_keys,
                           std::vector<EdgeKey>& keys, PreparedSubset* prepared,
                           ChunkedLoops* loops) {
  const bool made_before = prepared && prepared->metric;
  if (job.state.empty() && !made_before)
    throw_internal("sample_subset: a job without the master's state");
  const SampledEdges sampled = sampled_edges(job, free);
  SubsetSample out;
  out.inner_edges = sampled.inner_edges;
  if (sampled.edges.empty()) return out;
  PreparedSubset made = made_before ? std::move(*prepared) : prepare_subset(job, loops);
  CollapseMesh& local = *made.mesh;
  PriorityModule* module = made.metric.get();
  std::optional<KeyMemo> memo;
  if (carry_keys) {
    memo.emplace(*module, local.vertex_capacity());
    memo->reset(keys);
  }
  PriorityModule& costing = memo ? static_cast<PriorityModule&>(*memo) : *module;
  const CopyGroups groups = copy_groups_of(job.copy_group);
  Simplifier seams(local, costing, {});
  if (!groups.empty()) seams.join_copies(&groups);
  const size_t carried = keys.size();
  const Costing sample_costing = carry_keys ? Costing::kQueue : Costing::kEstimate;
  for (const auto& [a, b] : sampled.edges) {
    CollapseCandidate c;
    const bool placed = seams.cost_now(a, b, sample_costing, c);
    out.costs.push_back(placed ? c.cost : std::numeric_limits<double>::infinity());
    // A seam collapse's cost is no key of the module's, which cannot place the edge.
    const bool seam = groups.is_copy(a) && groups.is_copy(b);
    if (carry_keys)
      keys.push_back({a, b, placed && !seam ? c.cost : std::numeric_limits<double>::quiet_NaN()});
  }
  out.costings = module->costings();
  // Carried keys answered the edges they cover: those came back the same.
  if (keys.size() > carried) sort_unique_edges(keys);
  // (The memo and `seams` read the module and mesh where they stay: on the heap.)
  if (prepared) *prepared = std::move(made);
  return out;
}

SubsetSample sample_on_master(const SubsetJob& job, const SampledEdges& edges,
                              Simplifier& master_costs, const PriorityModule& master) {
  SubsetSample out;
  out.inner_edges = edges.inner_edges;
  const uint64_t costings_before = master.costings();
  out.costs.reserve(edges.edges.size());
  auto job_group = [&](VertexId v) { return job.copy_group.empty() ? kNoId : job.copy_group[v]; };
  for (const auto& [a, b] : edges.edges) {
    // Two locked copies whose groups are not both the job's: no collapse the job can make.
    const bool seam_elsewhere = !job.locked.empty() && job.locked[a] && job.locked[b] &&
                                (job_group(a) == kNoId || job_group(b) == kNoId);
    CollapseCandidate c;
    const bool placed =
        !seam_elsewhere &&
        master_costs.cost_now(job.global_vertex[a], job.global_vertex[b], Costing::kEstimate, c);
    out.costs.push_back(placed ? c.cost : std::numeric_limits<double>::infinity());
  }
  out.costings = master.costings() - costings_before;
  return out;
}

RoundCosts round_costs_of(const std::vector<SubsetSample>& samples, uint64_t remove,
                          double factor) {
  RoundCosts out;
  uint64_t total_edges = 0;
  std::vector<std::pair<double, double>> weighted;  // (cost, edges it stands for)
  for (const SubsetSample& s : samples) {
    total_edges += s.inner_edges;
    for (double c : s.costs)
      weighted.push_back({c, double(s.inner_edges) / double(s.costs.size())});
  }
  if (weighted.empty()) return out;
  std::sort(weighted.begin(), weighted.end());
  double total_weight = 0;
  for (const auto& w : weighted) total_weight += w.second;
  // The cost below which a fraction q of the edges lies: the first sampled cost whose
  // cumulative weight passes q (with equal weights, the floor(q n)-th smallest).
  auto quantile = [&](double q) {
    double sum = 0;
    for (const auto& [cost, weight] : weighted) {
      sum += weight;
      if (sum > q * total_weight) return cost;
    }
    return weighted.back().first;
  };
  // A collapse removes two faces and about three edges.
  const double fraction = std::min(1.0, double(remove) / 2 / double(total_edges));
  // At least the cost below which twice the round's collapses lie: where most sampled edges
  // cost nothing (coplanar quadrics), factor x 0 would stop every job at once.
  if (factor > 0)
    out.ceiling = std::max(factor * quantile(fraction), quantile(std::min(1.0, 2 * fraction)));
  const double cheap = quantile(std::min(1.0, kCheapEdgesPerCollapse * fraction));
  out.cheap_fraction.assign(samples.size(), 0.0);
  for (size_t s = 0; s < samples.size(); ++s) {
    const std::vector<double>& own = samples[s].costs;
    const auto below = std::count_if(own.begin(), own.end(), [&](double c) { return c <= cheap; });
    out.cheap_fraction[s] = own.empty() ? fraction : double(below) / double(own.size());
  }
  return out;
}

uint64_t set_targets(std::vector<SubsetJob>& jobs, const std::vector<uint64_t>& removable,
                     uint64_t faces_before, uint64_t goal,
                     const std::vector<double>& cheap_fraction) {
  const double fraction =
      faces_before > goal ? double(faces_before - goal) / double(faces_before) : 0.0;
  std::vector<double> fractions(jobs.size(), fraction);
  if (cheap_fraction.size() == jobs.size()) {
    double total = 0, weighted = 0;
    for (size_t s = 0; s < jobs.size(); ++s) {
      total += fraction * double(removable[s]);
      weighted += cheap_fraction[s] * double(removable[s]);
    }
    if (weighted > 0)
      for (size_t s = 0; s < jobs.size(); ++s)
        fractions[s] = std::min(0.95, total * cheap_fraction[s] / weighted);
  }
  uint64_t asked = 0;
  for (size_t s = 0; s < jobs.size(); ++s) {
    const auto share = uint64_t(std::llround(fractions[s] * double(removable[s])));
    const uint64_t faces = jobs[s].mesh.face_count();
    // 0 would mean "as far as legal": a job with nothing to remove keeps one face.
    jobs[s].options.target_faces = std::max<uint64_t>(1, faces > share ? faces - share : 0);
    asked += faces - jobs[s].options.target_faces;
  }
  return asked;
}

}  // namespace parapm
