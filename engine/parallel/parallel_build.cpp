#include "parallel/parallel_build.h"

#include <algorithm>

#include "parallel/parallel_builder.h"
#include "parallel/simplify_subset.h"
#include "util/job_pool.h"

namespace parapm {

std::vector<SubsetResult> ThreadPoolRunner::run(std::vector<SubsetJob>& jobs,
                                                const CancelToken* cancel) {
  std::vector<SubsetResult> results(jobs.size());
  const JobTeam team = team_min_items_ > 0
                           ? team_of_round(jobs.size(), cores_, threads_, team_min_items_)
                           : JobTeam{};
  std::vector<PreparedSubset> prepared = std::move(prepared_);
  prepared.resize(jobs.size());
  run_jobs(jobs.size(), threads_, [&](size_t i) {
    results[i] =
        simplify_subset(std::move(jobs[i]), {}, cancel, nullptr, team, std::move(prepared[i]));
    jobs[i] = SubsetJob{};  // its memory is not needed any more
  });
  return results;
}

uint32_t default_rounds(uint32_t p) { return p <= 2 ? 2 : 3; }

uint32_t scheduled_rounds(const ParallelOptions& parallel) {
  return parallel.rounds ? parallel.rounds : default_rounds(parallel.subsets);
}

uint64_t subset_faces_by_metric(bool costly_metric) { return costly_metric ? 4000 : 8000; }

double round_critical_seconds(const RoundStats& r) {
  return r.partition_seconds + r.append_seconds - r.partition_overlap_seconds +
         r.extract_critical_seconds + r.slowest_subset_cpu_seconds + r.merge_seconds -
         r.merge_overlap_seconds + r.band_pass_seconds + r.append_beyond_band_seconds;
}

double critical_path_seconds(const ParallelStats& st) {
  double seconds = st.setup_seconds;
  for (const RoundStats& r : st.round_stats) seconds += round_critical_seconds(r);
  return seconds + st.final_pass_seconds +
         std::max(0.0, st.final_append_seconds - st.final_work_seconds) + st.pm_build_seconds;
}

ProgressiveMesh build_progressive_mesh_parallel(
    const RepairedMesh& repaired, const SimplifyOptions& options, const ParallelOptions& requested,
    ParallelStats* stats, const ProgressCallback& progress, const CancelToken* cancel,
    SubsetRunner* runner, const ParallelEvents& events) {
  ParallelBuilder build(repaired, options, requested, stats, progress, cancel, runner, events);
  build.set_up();
  while (build.round()) {
  }
  build.final_pass();
  return build.progressive_mesh();
}

}  // namespace parapm
