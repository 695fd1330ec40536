// Parallel construction of a Progressive Mesh (Langis 1999, the "galaxy" method; METHOD.md
// section 4): in rounds, each on a new partition of the current mesh, simplify the subsets in
// parallel under a rule that keeps their collapses independent (the metric's state travelling
// in the jobs), merge the records by cost, replay them on the whole mesh and import the jobs'
// states; then finish the last borders with a sequential final pass. docs/ARCHITECTURE.md,
// "Parallel construction", says why each step is as it is.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "mesh/repair.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "pm/progressive_mesh.h"
#include "simplify/simplify.h"
#include "util/progress.h"

namespace parapm {

// ParallelOptions::min_subset_faces chosen by the metric (subset_faces_by_metric).
inline constexpr uint64_t kByMetric = ~uint64_t{0};

// The faces a subset needs to be worth its round: 4000 for a metric whose costings are costly
// (PriorityModule::costly(): the energy), 8000 for a cheap one (the quadric). A round's fixed
// work per face is about the same for both, and the quadric does a tenth of the energy's work
// per face, so it needs larger subsets to pay for it (decisions/notebook-2026-11.md, "Subset
// floors by the metric").
uint64_t subset_faces_by_metric(bool costly_metric);

struct ParallelOptions {
  uint32_t subsets = 2;  // p, in [1, 256]
  // Scheduled rounds, in [1, 64], each on a new partition of the current mesh (so the borders
  // move), the metric's state travelling in the jobs (job_state.h); 0: default_rounds(p).
  uint32_t rounds = 0;
  unsigned threads = 0;  // 0: min(p, hardware threads); the .pm does not depend on it
  // The scheduled rounds take the mesh from F faces down to max(target, handover_ratio x F),
  // geometrically (round r of R aims at F x handover_ratio^((r + 1) / R)); extra rounds and
  // the sequential final pass go on from there. In (0, 1].
  double handover_ratio = 0.1;
  // Past the handover, extra rounds step evenly (geometrically) on to the target while the
  // last round removed at least 90% of what it was asked, each with as many subsets (2 to p)
  // as keep at least this many faces each (2.5x this after a round that removed only half);
  // 0: no extra rounds. They shorten the sequential final pass on large meshes.
  uint64_t extra_round_subset_faces = 2000;
  // Every round cuts the mesh into at most (its faces / this) subsets; below 2 the rounds end
  // and the final pass does the rest. Why: a small subset is mostly border, which its job
  // cannot touch, so its round costs fixed work for few collapses. 0: p subsets in every
  // scheduled round; kByMetric: subset_faces_by_metric.
  uint64_t min_subset_faces = kByMetric;
  // A round ends early where its border band (the faces along its cut, which it cannot
  // remove: subset_rule.h) would hold more than this fraction of the faces it ends with in
  // excess: those faces stay at the round's starting resolution, costing precision elsewhere.
  // With a band of b x the faces, a round from S faces ends at E >= S / (1 + border_excess /
  // b), removing at least kMinRoundRemoval of its faces; a round so shortened does not count
  // against `rounds`. In [0, 0.5]; 0: the geometric rounds only (decisions/notebook-2026-11.md,
  // "Rounds bounded by their border band").
  double border_excess = 0.05;
  // Jobs leave alone edges costing more than this factor times the round's water level (the
  // cost below which a sample of the edges would give the round's collapses;
  // parallel_build.cpp, sample_round_costs), besides stopping at their share; 0: shares only.
  double water_level_factor = 8;
  // The round's faces divided among the jobs in proportion to their removable faces times
  // their fraction of cheap edges in the same sample (parallel_build.cpp, set_targets); off:
  // in proportion to their removable faces only.
  bool cost_shares = true;
  // Round 1's partition drawn beside round 0 (from the set-up on, on round 0's partition
  // graph: the mesh as round 0 found it; RoundStats::partition_foreseen); off: after round 0's
  // merge, on the mesh it left.
  bool early_partition = true;
  // After each round but the first, a sequential pass over the edges with a lagging end,
  // up to the 95th percentile of the round's costs (parallel_build.cpp).
  bool band_pass = true;
  // Queue keys still current after a round (no collapse changed an end of their edge) travel
  // into the next round's jobs and the final pass, which cost only the other edges
  // (edge_keys.h; the energy only: the quadric's costings are cheaper than carrying them).
  // Off (for measuring): every job costs every edge afresh, and the PM differs a little.
  bool carry_keys = true;
  // With carry_keys, the edges the jobs left deferred travel too (SubsetJob::deferred),
  // deferred again as the sequential build would hold them. Off: for measuring what it saves.
  bool carry_deferred = true;
  // A band pass's or the final pass's collapse that moves at least this many of the energy's
  // points projects them on a team of p chunks on the pool's threads, a job's of a round with
  // fewer than p subsets on a team of p / subsets chunks (ThreadPoolRunner) (the same PM: fewer
  // take less time than waking the team does); 0: none.
  uint32_t team_min_points = JobTeam::kDefaultMinItems;
  // The quadric's final pass on a compact copy of the live mesh (live_pass.h), the PM's base
  // read from the copy; off (for measuring and the tests): on the whole mesh's arrays. The same
  // PM either way.
  bool final_pass_on_live_copy = true;
  // Tests only: the master follows each round by re-running its module's collapsed() on every
  // merged record (the first step's path) instead of importing the jobs' returned states.
  bool replay_state = false;
};

struct SubsetTiming {
  uint32_t subset = 0;
  uint64_t faces = 0;  // of its job, halo included
  uint64_t owned_faces = 0;
  uint64_t collapses = 0;
  double wall_seconds = 0;
  double cpu_seconds = 0;
  std::string stop_reason;
};

struct RoundStats {
  uint32_t round = 0;
  uint64_t faces_before = 0;
  uint64_t goal_faces = 0;  // what the round aimed at
  // Faces its jobs were asked to remove: the round's fraction of those they can remove (not
  // their borders), so it ends above its goal (parallel_build.cpp, set_targets).
  uint64_t asked_faces = 0;
  uint64_t faces_after = 0;
  double partition_seconds = 0;  // with finding its border (bound_vertices, border_faces)
  // The previous round's subsets' lists, merged by cost, go into the PM's list beside its band
  // pass, or beside this round's partition or (round 1) jobs.
  double append_seconds = 0;
  // Drawn ahead, when the round has as many subsets as foreseen: beside the previous round's
  // band pass, on a copy of the mesh before it (partition_seconds then counts the copy), or,
  // for round 1 (round 0 has no band pass), beside round 0 from the set-up on, on round 0's
  // partition graph (the mesh as round 0 found it).
  bool partition_foreseen = false;
  // Round 0's partition is drawn beside the master's initialisation, round 1's beside the rest
  // of the set-up and round 0, a later round's beside the append or beside the last band pass:
  // what of it (and of the append) the critical path leaves out.
  double partition_overlap_seconds = 0;
  double extract_seconds = 0;  // jobs and their state, shares included (wall)
  // The edge sample (water level, shares), costed in the extraction's tasks: their CPU summed.
  double share_seconds = 0;
  // Each job's mesh and state are built on the pool: the slowest one's CPU, and the
  // extraction's share of the critical path (its sequential steps plus the slowest job).
  double slowest_extract_cpu_seconds = 0;
  double extract_critical_seconds = 0;
  double water_level = 0;  // the jobs' cost ceiling (ParallelOptions::water_level_factor)
  // Faces no job could remove (subset_rule.h, border_faces); with the goal raised to keep them
  // within ParallelOptions::border_excess when `border_limited`.
  uint64_t border_faces = 0;
  bool border_limited = false;
  double subsets_seconds = 0;  // wall time of the round's jobs
  double merge_seconds = 0;    // replay on the whole mesh, state import, keys
  // The subsets' replays run side by side, and beside the rest (state import, water level,
  // keys), on the pool's threads: what of it would overlap with a core per task (the critical
  // path leaves it out).
  double merge_overlap_seconds = 0;
  double slowest_subset_cpu_seconds = 0;
  uint64_t keys_carried = 0;         // queue keys given to the jobs (edge_keys.h)
  uint64_t deferred_carried = 0;     // deferred edges given to the jobs (SubsetJob::deferred)
  uint64_t keys_reused = 0;          // the jobs' queue costings answered by them
  uint64_t band_pass_collapses = 0;  // sequential, after the merge (ParallelOptions::band_pass)
  // The band pass alone (the append and the next partition beside it are the next round's
  // append_seconds and partition_seconds, the mesh's copy for that partition too).
  double band_pass_seconds = 0;
  // The append beside this round's band pass, when the partition drawn beside it was not
  // taken: what of it outlasted the band pass.
  double append_beyond_band_seconds = 0;
  std::vector<SubsetTiming> subsets;
};

struct ParallelStats {
  uint32_t subsets = 0;
  // Performed: fewer than asked at the handover, more with rounds shortened by their border
  // band (ParallelOptions::border_excess) and extra rounds.
  uint32_t rounds = 0;
  unsigned threads = 0;
  std::vector<RoundStats> round_stats;
  double setup_seconds = 0;  // the master's metric, initialised once on the whole mesh
  uint64_t final_pass_collapses = 0;
  // Whether it ran on a compact copy of the live mesh (ParallelOptions::final_pass_on_live_copy).
  bool final_pass_on_live_copy = false;
  double final_pass_seconds = 0;    // its set-up and its collapses
  double final_work_seconds = 0;    // its collapses
  double final_append_seconds = 0;  // the last round's records appended, beside the final pass
  double pm_build_seconds = 0;      // the PM's assembly, its loops at their critical path
  uint64_t collapses = 0;
  std::string stop_reason;  // of the final pass
  double seconds = 0;       // the whole construction, wall
  double cpu_seconds = 0;   // the subsets' CPU plus the master's (partition, merge, final pass)
  // Edges costed by every module of the build (PriorityModule::costings): the jobs', their
  // edge samples', the master's (band passes, final pass). Deterministic, unlike cpu_seconds:
  // the build's work, to compare with SimplifyStats::costings of the sequential build.
  uint64_t costings = 0;
  // What the build would take with one processor per subset (critical_path_seconds below).
  double critical_path_seconds = 0;
};

// The critical path of a build whose stages `stats` timed: the set-up, then per round
// (round_critical_seconds) the partition (or the previous round's append, if longer),
// extraction (its sequential steps and the slowest job's), the slowest subset's CPU, the merge
// and the band pass, then the final pass (or the last append) and the PM assembly. CPU of the
// jobs, not wall: on a loaded machine wall time is not the job's.
double round_critical_seconds(const RoundStats& round);
double critical_path_seconds(const ParallelStats& stats);

// Where a round's subset jobs run. The in-process build runs them on a thread pool; the
// coordinator sends them to worker daemons. Whatever runs them, results[i] must be
// simplify_subset(jobs[i])'s (exactly: the build stays deterministic only then).
class SubsetRunner {
 public:
  virtual ~SubsetRunner() = default;
  // May move from `jobs`. Throws Error(kCancelled / kDeadlineExceeded) when `cancel` fires,
  // another Error when a job cannot be run anywhere.
  virtual std::vector<SubsetResult> run(std::vector<SubsetJob>& jobs,
                                        const CancelToken* cancel) = 0;
};

// Runs the jobs with simplify_subset on a pool of `threads` threads (0: one per subset, up to
// the hardware's). A round of fewer jobs than `cores` (the build's p: a core per subset) gives
// each job a team (JobTeam) of cores / jobs chunks on the threads the pool leaves idle, loops
// of at least `team_min_items` points (0: no teams): the tail rounds' few jobs, whose
// collapses each move hundreds of the energy's points, use the cores the round leaves.
class ThreadPoolRunner : public SubsetRunner {
 public:
  explicit ThreadPoolRunner(unsigned threads, unsigned cores = 0, size_t team_min_items = 0)
      : threads_(threads), cores_(cores), team_min_items_(team_min_items) {}
  std::vector<SubsetResult> run(std::vector<SubsetJob>& jobs, const CancelToken* cancel) override;
  // The next run's jobs' meshes and metrics, made by their round's samples (empty where none):
  // the jobs take them instead of importing their states again.
  void take_prepared(std::vector<PreparedSubset> prepared) { prepared_ = std::move(prepared); }

 private:
  std::vector<PreparedSubset> prepared_;
  unsigned threads_;
  unsigned cores_;
  size_t team_min_items_;
};

// What a build tells an observer as it goes (for a job's event stream); all optional, called
// on the building thread.
struct ParallelEvents {
  std::function<void(uint32_t round, uint32_t subsets, uint64_t faces)> partitioned;
  std::function<void(const RoundStats& round)> merged;  // after the merge and band pass
  std::function<void(uint64_t collapses, double seconds)> final_pass_done;
};

// The rounds of ParallelOptions::rounds = 0: two at p = 2, three above. Fewer, larger rounds
// leave fewer cuts to mend and less fixed work per round (partition, extraction, merge, band
// pass); with more subsets a round's shares follow the sequential order less closely the more
// it removes, so p > 2 takes three (decisions/notebook-2026-11.md, "Two rounds at p = 2").
uint32_t default_rounds(uint32_t p);
// The rounds a build with these options schedules: `rounds`, or default_rounds(subsets).
uint32_t scheduled_rounds(const ParallelOptions& parallel);

// Same contract as build_progressive_mesh (simplify.h), whose options it takes; the result is
// a valid, lossless PM reaching the same target. Deterministic: the same input, options, p
// and rounds give the same PM whatever the thread count, timing and `runner` (null: a
// ThreadPoolRunner of parallel.threads). Throws
// Error(kInvalidInput) for bad options (p outside [1, 256] or above the vertex count, rounds
// above 64, handover_ratio outside (0, 1]).
ProgressiveMesh build_progressive_mesh_parallel(
    const RepairedMesh& repaired, const SimplifyOptions& options, const ParallelOptions& parallel,
    ParallelStats* stats = nullptr, const ProgressCallback& progress = {},
    const CancelToken* cancel = nullptr, SubsetRunner* runner = nullptr,
    const ParallelEvents& events = {});

}  // namespace parapm
