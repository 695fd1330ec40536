// What a round of the parallel construction asks of its jobs (parallel_build.cpp): a sample of
// its edges' costs, taken by the jobs' own modules side by side, sets the jobs' cost ceiling
// (the water level) and their shares of the round's faces (by their cheap edges).
#pragma once

#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "parallel/edge_keys.h"
#include "parallel/subset_job.h"
#include "simplify/simplifier.h"

namespace parapm {

struct PreparedSubset;  // simplify_subset.h

// What a sample of a round's edges says about its costs: the live inner edges (both ends in
// one subset), represented by those with two free ends (every stride-th of them, about
// kSampledEdgesPerSubset per subset).
struct RoundCosts {
  // The jobs' cost ceiling: `factor` times the water level, the cost below which the sampled
  // edges, scaled to all edges, would give the round's collapses. A sequential run, cheapest
  // first, would not go far above it in this round (the costs of the edges it creates grow,
  // hence the factor); a subset whose region holds few cheap collapses would, if it had to
  // remove its share of the faces whatever they cost. Infinite if `factor` is 0.
  double ceiling = std::numeric_limits<double>::infinity();
  // Per subset, the fraction of its sampled edges that are cheap: among the cheapest
  // kCheapEdgesPerCollapse edges per collapse of the round, all subsets' edges ranked
  // together (set_targets).
  std::vector<double> cheap_fraction;
};

// Cheap edges counted per collapse of the round: a sequential run's costs grow as a region
// coarsens, so the collapses it makes in a region follow the edges there below a cost a few
// times the round's first quantile (the value: decisions/notebook-2026-11.md, "Shares by cheap
// edges").
constexpr double kCheapEdgesPerCollapse = 2.5;
// Edges sampled per subset: enough for its share to be stable (decisions/notebook-2026-11.md, "The
// edge sample, fewer edges").
constexpr uint64_t kSampledEdgesPerSubset = 1024;

// One subset's part of the sample: its inner edges, and the costs of every stride-th of those
// with two free ends. Only those: the job costs only them and joins their costs to its keys,
// so no sampled costing is wasted. Each cost stands for inner_edges / costs.size() edges: the
// subset's free edges cost alike, for the round's quantiles, as all its inner edges.
struct SubsetSample {
  uint64_t inner_edges = 0;
  uint64_t costings = 0;      // edges the sample's module costed (the carried keys answer others)
  std::vector<double> costs;  // infinite: no collapse of the edge could be costed
};

// The edges a subset's sample costs: every stride-th of its inner edges with two free ends
// (local ids, a < b, in the job's face order), about kSampledEdgesPerSubset of them, and the
// count of its inner edges.
struct SampledEdges {
  uint64_t inner_edges = 0;
  std::vector<std::pair<VertexId, VertexId>> edges;
};
SampledEdges sampled_edges(const SubsetJob& job, const std::vector<uint8_t>& free);

// The sample of a job's subset (a job with the master's state: Error(kInternal) otherwise),
// costed by the job's own module, imported from the job's state as simplify_subset imports
// it, so that the subsets' samples are costed side by side (in the extraction's tasks), not
// one after the other on the master's critical path. An edge between copies of two groups is
// costed as the seam collapse the job would make of it (Simplifier::cost_now): a subset
// whose copies simplify only by seam collapses is as cheap as they are.
// `free`: free_vertices of the job. `keys` (with carry_keys): the job's carried keys (local
// ids, sorted), which answer the edges they cover; the sampled edges join them, so that the
// job does not cost them again (its module costs them alike: same state). Costed as
// Costing::kEstimate, or with carry_keys as kQueue: those costs become the job's queue keys.
// `prepared` (may be null): given the job's mesh and metric the sample was costed on, for a job
// run in the same process (simplify_subset takes them); left as it was when no edge is sampled.
// One that holds them already (prepare_subset's, its state read from the master) is costed on
// and given back; the job then needs no state.
// `loops` (null: one thread): the state's import in its chunks.
SubsetSample sample_subset(const SubsetJob& job, const std::vector<uint8_t>& free, bool carry_keys,
                           std::vector<EdgeKey>& keys, PreparedSubset* prepared = nullptr,
                           ChunkedLoops* loops = nullptr);

// The same sample costed on the whole mesh by `master_costs`, a Simplifier over it with the
// master's module and the build's copy groups (`edges` from sampled_edges(job, ...),
// translated to global ids; a seam collapse only between groups that are the job's): the
// costs the job's own module would give (its state is the master's, job_state.h), without
// building the job's mesh and module a second time. For a cheap metric
// (PriorityModule::costly() false: the quadric, whose sampled costs never travel as keys), for
// which those copies cost more than the costings. Not thread-safe (the master's module);
// out.costings counts the master's costings of it.
SubsetSample sample_on_master(const SubsetJob& job, const SampledEdges& edges,
                              Simplifier& master_costs, const PriorityModule& master);

// The round's costs from its subsets' samples (one per job, in order), each sampled edge
// standing for its subset's inner edges over its sampled ones; `remove`: the faces the round
// removes, `factor`: the water level's factor (0: no ceiling). Deterministic.
RoundCosts round_costs_of(const std::vector<SubsetSample>& samples, uint64_t remove, double factor);

// Each subset removes a share of the faces it can remove (not of all its faces: asked for its
// border too, a job would coarsen its inside further to make up, and the round's level would
// be uneven), so that its inside leaves the round as coarse as the whole mesh should; its
// border stays finer, for the next round's partition or the final pass to take, cheapest
// first, as a sequential run would have. Without `cheap_fraction`, every share is the round's
// fraction (faces_before - goal) / faces_before of the subset's removable faces. With it, the
// same total is divided in proportion to the subset's removable faces times its fraction of
// cheap edges (at most 95% of its removable faces): a sequential run takes more from a flat
// region than from a curved one (decisions/notebook-2026-11.md, "Shares of the removable faces",
// "Shares by cheap edges"). Returns the faces asked of all jobs.
uint64_t set_targets(std::vector<SubsetJob>& jobs, const std::vector<uint64_t>& removable,
                     uint64_t faces_before, uint64_t goal,
                     const std::vector<double>& cheap_fraction);

}  // namespace parapm
