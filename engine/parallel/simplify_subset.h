// The worker's function of the parallel construction: simplify one subset job under the
// subset rule (subset_rule.h) and return its collapse records in the whole mesh's ids. The
// in-process build runs it on a thread pool; a worker daemon will run exactly this.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "parallel/subset_job.h"
#include "simplify/modules.h"
#include "simplify/simplifier.h"
#include "simplify/simplify.h"
#include "util/progress.h"

namespace parapm {

struct SubsetResult {
  uint32_t round = 0;
  uint32_t subset = 0;
  // In the order performed, in global ids (vs, vt, vl, vr, fl, fr, corner and changed
  // wedges), with their costs: ready to be merged (collapse_merge.h) or streamed.
  std::vector<CollapseRecord> records;
  // With a job state: the metric's state at the end, of what the job changed, in global ids
  // (job_state.h, export_result_state). Empty otherwise.
  MetricState state;
  // The queue keys still current at the end (edge_keys.h), in global ids, sorted by (a, b);
  // the next round's jobs take those of their free edges instead of costing them again.
  std::vector<EdgeKey> keys;
  // With keys: the edges the job left deferred (Simplifier::deferred_edges()) from a finite
  // key, in global ids, sorted; the next round's jobs queue them deferred (SubsetJob::deferred).
  std::vector<DeferredEdge> deferred;
  uint64_t keys_reused = 0;  // queue costings the job answered from the job's keys
  uint64_t costings = 0;     // edges the job's metric costed (PriorityModule::costings)
  uint64_t faces = 0;        // of the job's mesh, halo included
  uint64_t owned_faces = 0;  // of those, the faces with three owned vertices
  uint64_t free_vertices = 0;
  SimplifierStats stats;
  double wall_seconds = 0;
  double cpu_seconds = 0;  // of the calling thread (CLOCK_THREAD_CPUTIME_ID)
  // With a JobTeam: what its loops took beyond their time with a core per chunk (the
  // critical path counts cpu_seconds less this), and the CPU its own threads spent.
  double team_saved_seconds = 0;
  double team_cpu_seconds = 0;
};

// The cores a job may use beside its own thread: its metric's point projections (the energy's,
// PriorityModule::use_team) cut into `chunks` on `threads` threads (the caller's among them),
// loops of at least `min_items` points; and its state's passes (job_state.h: import, export) in
// as many chunks of at least kStateChunkItems faces or points. The same records and state
// whatever the team.
constexpr size_t kStateChunkItems = 256;
struct JobTeam {
  // The smallest loop worth a team: fewer points take less time than waking it does.
  static constexpr size_t kDefaultMinItems = 512;
  unsigned chunks = 1;  // 1: no team
  unsigned threads = 1;
  size_t min_items = 0;
};
// A job's team in a round of `jobs` jobs on `cores` cores (the build's p) and `threads` threads:
// cores / jobs chunks on its share of the threads; no team (one chunk) when the jobs are as many
// as the cores or more.
JobTeam team_of_round(size_t jobs, unsigned cores, unsigned threads, size_t min_items);
// The chunks a job's state passes (job_state.h) run in with `team`.
ChunkedLoops state_loops_of(const JobTeam& team);

// A job's working mesh and its metric, the job's state imported (job_module), made before the
// job runs: the round's sample (round_shares.h, sample_subset) costs edges on them, and
// simplify_subset(SubsetJob&&) in the same process takes them instead of importing the state a
// second time. Costings on the metric leave it as it was but for its caches. Never sent: a
// worker imports its own.
struct PreparedSubset {
  std::unique_ptr<CollapseMesh> mesh;  // (on the heap: the metric may hold its address)
  std::unique_ptr<PriorityModule> metric;
  bool imported = false;  // the metric holds the job's state
};
PreparedSubset prepare_subset(const SubsetJob& job, ChunkedLoops* loops = nullptr,
                              const PriorityModule* master = nullptr);

// Throws Error(kInvalidInput) for an invalid job or options, Error(kCancelled /
// kDeadlineExceeded) when `cancel` fires. Thread-safe: jobs share nothing. With
// `free_quadrics` and a quadric job: its free vertices' quadrics at its end, in global ids
// (what a worker keeps between rounds: held_state.h); left empty otherwise.
SubsetResult simplify_subset(const SubsetJob& job, const ProgressCallback& progress = {},
                             const CancelToken* cancel = nullptr,
                             QuadricState* free_quadrics = nullptr);
// The same, releasing the job's mesh, state and keys as soon as its working mesh and metric
// hold them (a job's peak memory holds them once, not twice); `job` keeps its ids, owned and
// locked flags and options. `prepared` (empty: none): prepare_subset(job)'s, taken as
// the job's working mesh and metric (the job's state may then be gone: the metric holds it).
SubsetResult simplify_subset(SubsetJob&& job, const ProgressCallback& progress = {},
                             const CancelToken* cancel = nullptr,
                             QuadricState* free_quadrics = nullptr, const JobTeam& team = {},
                             PreparedSubset prepared = {});

// The options a job's metric is made with (Error(kInvalidInput) for invalid ones).
SimplifyOptions simplify_options_of(const SubsetOptions& subset);

// The job's metric module over `working` (a CollapseMesh of job.mesh), as simplify_subset
// makes it: with a job state, the master's state imported (not yet initialised otherwise), in
// `loops`' chunks (null: one thread). With `master` (in this process, where
// imports_from_master(*master, job)), the state is read from it instead of job.state.
std::unique_ptr<PriorityModule> job_module(const SubsetJob& job, const CollapseMesh& working,
                                           ChunkedLoops* loops = nullptr,
                                           const PriorityModule* master = nullptr);

}  // namespace parapm
