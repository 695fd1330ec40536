#include "parallel/parallel_build.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <spdlog/spdlog.h>

#include "parallel/collapse_merge.h"
#include "parallel/job_pool.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "partition/partition.h"
#include "simplify/modules.h"
#include "simplify/pm_builder.h"
#include "simplify/simplifier.h"
#include "util/error.h"

namespace parapm {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The master's priority module, already initialised and brought up to date by the replay:
// the final pass continues with its state instead of starting afresh.
class ContinuedPriority : public PriorityModule {
 public:
  explicit ContinuedPriority(PriorityModule& inner) : inner_(inner) {}
  std::string name() const override { return inner_.name(); }
  void initialize(const CollapseMesh&) override {}
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b,
                CollapseCandidate& out) const override {
    return inner_.evaluate(mesh, a, b, out);
  }
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                 const EdgeFaces& edge) override {
    inner_.collapsed(mesh, done, edge);
  }

 private:
  PriorityModule& inner_;
};

void check_parallel_options(const ParallelOptions& parallel, size_t vertices) {
  if (parallel.subsets < 1 || parallel.subsets > kMaxPartitionSubsets)
    throw_invalid("the subset count p must be in [1, 256], got " +
                  std::to_string(parallel.subsets));
  if (parallel.subsets > vertices)
    throw_invalid("the subset count p = " + std::to_string(parallel.subsets) +
                  " exceeds the vertex count " + std::to_string(vertices));
  if (parallel.rounds != 1)
    throw_invalid("parallel rounds: only 1 is supported so far, got " +
                  std::to_string(parallel.rounds));
  if (!(parallel.handover_ratio > 0 && parallel.handover_ratio <= 1))
    throw_invalid("the handover ratio must be in (0, 1], got " +
                  std::to_string(parallel.handover_ratio));
}

// Each subset removes its share of the round's faces, in proportion to the faces the
// partition gave it (partition.h: each face to exactly one subset).
void set_targets(std::vector<SubsetJob>& jobs, const Partition& partition, uint64_t faces_before,
                 uint64_t goal) {
  std::vector<uint64_t> assigned(jobs.size(), 0);
  for (uint32_t s : partition.face_subset) ++assigned[s];
  const uint64_t remove = faces_before > goal ? faces_before - goal : 0;
  for (size_t s = 0; s < jobs.size(); ++s) {
    const auto share = uint64_t(std::llround(double(remove) * double(assigned[s]) /
                                             double(std::max<uint64_t>(1, faces_before))));
    const uint64_t faces = jobs[s].mesh.face_count();
    // 0 would mean "as far as legal": a job with nothing to remove keeps one face.
    jobs[s].options.target_faces = std::max<uint64_t>(1, faces > share ? faces - share : 0);
  }
}

}  // namespace

ProgressiveMesh build_progressive_mesh_parallel(
    const RepairedMesh& repaired, const SimplifyOptions& options, const ParallelOptions& parallel,
    ParallelStats* stats, const ProgressCallback& progress, const CancelToken* cancel) {
  const auto start = std::chrono::steady_clock::now();
  const double master_cpu_start = thread_cpu_seconds();
  check_simplify_options(options);
  const Mesh& mesh = repaired.mesh;
  check_parallel_options(parallel, mesh.vertex_count());
  ParallelStats local_stats;
  ParallelStats& st = stats ? *stats : local_stats;
  st = {};
  st.subsets = parallel.subsets;
  st.rounds = parallel.rounds;
  st.threads = pool_threads(parallel.threads, parallel.subsets);

  const uint64_t input_faces = mesh.face_count();
  const uint64_t target = target_face_count(input_faces, options);
  const uint64_t handover = std::max<uint64_t>(
      target, uint64_t(std::llround(parallel.handover_ratio * double(input_faces))));
  const std::vector<uint8_t> locked = locked_vertices(repaired);

  // The whole mesh and the master's copy of the metric, which follows every merged collapse
  // so that the final pass continues from the state a sequential run would have.
  CollapseMesh whole(mesh);
  std::unique_ptr<PriorityModule> master = make_priority_module(options, mesh, locked);
  master->initialize(whole);

  SubsetOptions subset_options;
  subset_options.metric = options.metric;
  subset_options.samples_per_face = options.samples_per_face;
  subset_options.crease_angle_degrees = options.crease_angle_degrees;
  subset_options.attribute_weight = options.attribute_weight;
  subset_options.seed = options.seed;
  subset_options.reference_diagonal = bounding_box(mesh).diagonal();

  std::vector<CollapseRecord> records;
  double subsets_cpu = 0;
  for (uint32_t round = 0; round < parallel.rounds; ++round) {
    RoundStats rs;
    rs.round = round;
    rs.faces_before = whole.live_faces();
    if (rs.faces_before <= handover) break;
    // Geometric steps from the present face count to the handover.
    rs.goal_faces = uint64_t(
        std::llround(double(rs.faces_before) * std::pow(double(handover) / double(rs.faces_before),
                                                        1.0 / double(parallel.rounds - round))));

    auto t = std::chrono::steady_clock::now();
    PartitionOptions partition_options;
    partition_options.seed = options.seed + round;
    const Partition partition = partition_mesh(mesh, parallel.subsets, partition_options);
    rs.partition_seconds = seconds_since(t);

    t = std::chrono::steady_clock::now();
    std::vector<SubsetJob> jobs =
        extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float, locked,
                        partition.vertex_subset, partition.subsets, round, subset_options);
    set_targets(jobs, partition, rs.faces_before, rs.goal_faces);
    rs.extract_seconds = seconds_since(t);

    t = std::chrono::steady_clock::now();
    std::vector<SubsetResult> results(jobs.size());
    run_jobs(jobs.size(), parallel.threads, [&](size_t i) {
      results[i] = simplify_subset(jobs[i], {}, cancel);
      jobs[i] = SubsetJob{};  // its memory is not needed any more
    });
    rs.subsets_seconds = seconds_since(t);
    if (cancel) cancel->check();

    t = std::chrono::steady_clock::now();
    std::vector<std::vector<CollapseRecord>> lists;
    lists.reserve(results.size());
    for (SubsetResult& r : results) {
      rs.subsets.push_back({r.subset, r.faces, r.owned_faces, r.records.size(), r.wall_seconds,
                            r.cpu_seconds, r.stats.stop_reason});
      subsets_cpu += r.cpu_seconds;
      lists.push_back(std::move(r.records));
    }
    std::vector<CollapseRecord> merged = merge_by_cost(std::move(lists));
    const ReplayReport replay = replay_collapses(whole, merged, master.get());
    records.insert(records.end(), std::make_move_iterator(merged.begin()),
                   std::make_move_iterator(merged.end()));
    rs.merge_seconds = seconds_since(t);
    rs.faces_after = whole.live_faces();
    spdlog::debug(
        "parallel round {}: {} subsets {}->{} faces (goal {}), partition {:.3f} s, extract "
        "{:.3f} s, subsets {:.3f} s, merge {:.3f} s ({} attribute mismatches)",
        round, parallel.subsets, rs.faces_before, rs.faces_after, rs.goal_faces,
        rs.partition_seconds, rs.extract_seconds, rs.subsets_seconds, rs.merge_seconds,
        replay.attribute_mismatches);
    st.round_stats.push_back(std::move(rs));
    if (progress) progress(input_faces - whole.live_faces(), input_faces - target);
  }

  // The final pass: the borders and whatever remains down to the target, sequentially.
  auto t = std::chrono::steady_clock::now();
  ContinuedPriority continued(*master);
  Simplifier final_pass(whole, continued, standard_constraints(locked));
  SimplifierLimits limits;
  limits.target_faces = target;
  const uint64_t done_before = input_faces - whole.live_faces();
  std::vector<CollapseRecord> final_records = final_pass.run(
      limits,
      [&](uint64_t done, uint64_t) {
        if (progress) progress(done_before + done, input_faces - target);
      },
      cancel);
  st.final_pass_collapses = final_records.size();
  st.final_pass_seconds = seconds_since(t);
  st.stop_reason = final_pass.stats().stop_reason;
  records.insert(records.end(), std::make_move_iterator(final_records.begin()),
                 std::make_move_iterator(final_records.end()));

  t = std::chrono::steady_clock::now();
  PmBuildOptions build_options;
  build_options.keep_order = options.keep_order;
  ProgressiveMesh pm = build_pm_from_collapses(repaired, whole, records, build_options);
  pm.info.metric = master->name();
  st.pm_build_seconds = seconds_since(t);
  st.collapses = records.size();
  st.seconds = seconds_since(start);
  st.cpu_seconds = subsets_cpu + (thread_cpu_seconds() - master_cpu_start);
  pm.info.seconds = st.seconds;
  spdlog::debug(
      "parallel build p={} rounds={}: {} -> {} faces in {:.3f} s ({:.3f} s CPU), final pass {} "
      "collapses in {:.3f} s ({})",
      parallel.subsets, parallel.rounds, input_faces, pm.base.face_count(), st.seconds,
      st.cpu_seconds, st.final_pass_collapses, st.final_pass_seconds, st.stop_reason);
  return pm;
}

}  // namespace parapm
