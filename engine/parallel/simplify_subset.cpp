#include "parallel/simplify_subset.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include <spdlog/spdlog.h>

#include "parallel/job_state.h"
#include "parallel/subset_rule.h"
#include "simplify/quadric_priority.h"
#include "simplify/simplify.h"
#include "util/clock.h"
#include "util/error.h"
#include "util/job_pool.h"
#include "util/thread_team.h"

namespace parapm {
namespace {

// Still sorted: local ids follow the global order.
std::vector<EdgeKey> current_keys_in_global_ids(const KeyMemo& memo, const CollapseMesh& mesh,
                                                const SubsetJob& job) {
  std::vector<EdgeKey> keys = memo.current_keys(mesh);
  for (EdgeKey& k : keys) {
    k.a = job.global_vertex[k.a];
    k.b = job.global_vertex[k.b];
  }
  return keys;
}

}  // namespace

SimplifyOptions simplify_options_of(const SubsetOptions& subset) {
  SimplifyOptions options;
  copy_metric_options(subset, options);
  options.free_placement_above_faces = subset.free_placement ? 0 : UINT64_MAX;
  check_simplify_options(options);
  return options;
}

std::unique_ptr<PriorityModule> job_module(const SubsetJob& job, const CollapseMesh& working,
                                           ChunkedLoops* loops, const PriorityModule* master) {
  std::unique_ptr<PriorityModule> module = make_priority_module(
      simplify_options_of(job.options), job.mesh, job.locked, job.options.reference_diagonal);
  if (master)
    import_from_master(*module, working, job, *master, loops);
  else if (!job.state.empty())
    import_job_state(*module, working, job, loops);
  return module;
}

JobTeam team_of_round(size_t jobs, unsigned cores, unsigned threads, size_t min_items) {
  JobTeam team;
  if (jobs == 0 || jobs >= cores) return team;
  team.chunks = unsigned(cores / jobs);
  team.threads = std::max<unsigned>(1, pool_threads(threads, cores) / unsigned(jobs));
  team.min_items = min_items;
  return team;
}

ChunkedLoops state_loops_of(const JobTeam& team) {
  return team.chunks > 1 ? ChunkedLoops(team.chunks, team.threads, kStateChunkItems)
                         : ChunkedLoops();
}

PreparedSubset prepare_subset(const SubsetJob& job, ChunkedLoops* loops,
                              const PriorityModule* master) {
  PreparedSubset prepared;
  prepared.mesh = std::make_unique<CollapseMesh>(job.mesh);
  prepared.metric = job_module(job, *prepared.mesh, loops, master);
  prepared.imported = master || !job.state.empty();
  return prepared;
}

namespace {

// `release` (null, or `job` itself when the caller gives it up): its mesh, state and keys are
// released once the working mesh, the module and the memo hold them.
SubsetResult simplify(const SubsetJob& job, SubsetJob* release, const ProgressCallback& progress,
                      const CancelToken* cancel, QuadricState* free_quadrics,
                      const JobTeam& job_team, PreparedSubset prepared) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_seconds();
  validate_subset_job(job);
  const SimplifyOptions options = simplify_options_of(job.options);

  SubsetResult result;
  result.round = job.round;
  result.subset = job.subset;
  result.faces = job.mesh.face_count();
  result.owned_faces = job.owned_faces;
  std::vector<uint8_t> free_vertex = free_vertices(job.mesh, job.owned);
  for (uint8_t f : free_vertex) result.free_vertices += f;
  if (free_quadrics) {
    *free_quadrics = QuadricState{};
    if (job.options.metric == "quadric")
      for (VertexId v = 0; v < free_vertex.size(); ++v)
        if (free_vertex[v]) free_quadrics->vertices.push_back(v);
  }

  std::optional<ThreadTeam> team;  // outlives the metric, which uses it
  // The state's passes over the points on the team's cores, in chunks of their own.
  ChunkedLoops state_loops = state_loops_of(job_team);
  PreparedSubset ready = prepared.metric ? std::move(prepared) : prepare_subset(job, &state_loops);
  if (ready.mesh->vertex_capacity() != job.mesh.vertex_count())
    throw_internal("simplify_subset: a prepared mesh of another job");
  CollapseMesh& working = *ready.mesh;
  const std::unique_ptr<PriorityModule>& metric = ready.metric;
  const uint64_t costings_before = metric->costings();  // (a sample's, if prepared)
  if (job_team.chunks > 1 && job_team.min_items > 0 && metric->costly()) {
    team.emplace(job_team.chunks, job_team.threads, job_team.min_items);
    metric->use_team(&*team);
  }
  // With a state, the metric is the master's over the job: imported, not initialised.
  std::unique_ptr<PriorityModule> imported;
  const bool had_state = ready.imported;
  if (had_state) imported = without_initialize(*metric);
  PriorityModule& module = imported ? *imported : *metric;
  std::optional<KeyMemo> memo;  // only for a metric whose keys are worth carrying (costly())
  if (metric->costly()) {
    memo.emplace(module, working.vertex_capacity());
    memo->reset(job.keys);
  }
  if (release) {
    // The working mesh, the module and the memo hold copies: the job's own would only add to
    // a job's memory.
    release->mesh = Mesh{};
    release->state = MetricState{};
    release->keys = std::vector<EdgeKey>{};
  }
  std::unique_ptr<PriorityModule> priority =
      make_subset_priority(memo ? *memo : module, std::move(free_vertex));
  auto constraints = standard_constraints(job.locked);
  constraints.push_back(make_subset_constraint(job.owned));
  const CopyGroups groups = copy_groups_of(job.copy_group);
  std::optional<Simplifier> simplifier;
  simplifier.emplace(working, *priority, std::move(constraints));
  if (!groups.empty()) simplifier->join_copies(&groups);
  SimplifierLimits limits;
  limits.target_faces = job.options.target_faces;
  if (job.options.max_cost > 0) limits.max_cost = job.options.max_cost;
  if (job.options.defer_recosting) limits.defer_above_faces = 0;
  limits.first_deferred = &job.deferred;
  result.records = simplifier->run(limits, progress, cancel);
  // Keys mean something to the master only when the job's state is the master's.
  if (memo && had_state) {
    result.keys = current_keys_in_global_ids(*memo, working, job);
    // But those the module refused last (infinite key): the next round's jobs cost them at
    // once, as before, rather than wait for their queues to empty.
    for (const DeferredEdge& d : simplifier->deferred_edges())
      if (!std::isinf(d.key))  // still sorted: local ids follow the global order
        result.deferred.push_back({job.global_vertex[d.a], job.global_vertex[d.b], d.key});
  }
  result.keys_reused = memo ? memo->reused() : 0;
  result.stats = simplifier->stats();
  // The queue, the keys and the metric's caches go before the state is exported: the job's
  // exported state takes their place at its peak, not a place beside them.
  simplifier.reset();
  priority.reset();
  memo.reset();
  metric->release_caches();
  if (had_state)
    result.state = export_result_state(*metric, working, job, result.records, &state_loops);
  if (free_quadrics && !free_quadrics->vertices.empty()) {
    const auto& quadrics = dynamic_cast<const QuadricPriority&>(*metric);
    free_quadrics->quadrics.reserve(free_quadrics->vertices.size());
    for (VertexId& v : free_quadrics->vertices) {
      free_quadrics->quadrics.push_back(quadrics.quadric(v));
      v = job.global_vertex[v];
    }
  }
  for (CollapseRecord& r : result.records) to_global_ids(r, job);
  result.costings = metric->costings() - costings_before;
  result.wall_seconds = seconds_since(start);
  result.cpu_seconds = thread_cpu_seconds() - cpu_start;
  if (team) {
    result.team_saved_seconds = team->saved_seconds();
    result.team_cpu_seconds = team->worker_cpu_seconds();
  }
  result.team_saved_seconds += state_loops.seconds() - state_loops.critical_seconds();
  spdlog::debug(
      "round {} subset {} simplified {}->{} faces ({} owned, {} free vertices) in {:.3f} s"
      " ({:.3f} s CPU; {} collapses, {} seam collapses, {} evaluations, {} deferred, {} keys "
      "reused; {})",
      job.round, job.subset, result.faces, working.live_faces(), result.owned_faces,
      result.free_vertices, result.wall_seconds, result.cpu_seconds, result.stats.collapses,
      result.stats.seam_collapses, result.stats.evaluations, result.stats.deferred,
      result.keys_reused, result.stats.stop_reason);
  return result;
}

}  // namespace

SubsetResult simplify_subset(const SubsetJob& job, const ProgressCallback& progress,
                             const CancelToken* cancel, QuadricState* free_quadrics) {
  return simplify(job, nullptr, progress, cancel, free_quadrics, {}, {});
}

SubsetResult simplify_subset(SubsetJob&& job, const ProgressCallback& progress,
                             const CancelToken* cancel, QuadricState* free_quadrics,
                             const JobTeam& team, PreparedSubset prepared) {
  return simplify(job, &job, progress, cancel, free_quadrics, team, std::move(prepared));
}

}  // namespace parapm
