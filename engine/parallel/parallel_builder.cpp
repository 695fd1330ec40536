#include "parallel/parallel_builder.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <future>
#include <limits>
#include <memory>

#include <spdlog/spdlog.h>

#include "parallel/collapse_merge.h"
#include "parallel/edge_keys.h"
#include "parallel/job_state.h"
#include "parallel/live_pass.h"
#include "parallel/round_shares.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "parallel/subset_rule.h"
#include "partition/partition.h"
#include "simplify/energy_priority.h"
#include "simplify/modules.h"
#include "simplify/pm_builder.h"
#include "simplify/quadric_priority.h"
#include "simplify/simplifier.h"
#include "simplify/surface_samples.h"
#include "util/clock.h"
#include "util/error.h"
#include "util/fresh_pages.h"
#include "util/job_pool.h"
#include "util/memory.h"
#include "util/number_text.h"

namespace parapm {
namespace {

// The live part of a mesh as a plain mesh (what the partitioner takes), and per vertex of the
// mesh its id there (kNoId for dead vertices). The live copies of a group (copy_groups.h) are
// one vertex there: its sheets join, and the partition gives all the copies to one subset,
// whose jobs may then make their seam collapses.
struct LiveCopy {
  Mesh mesh;
  std::vector<VertexId> compact;
};
// The repaired mesh as a CollapseMesh built from it first shows it (every face alive, a
// vertex alive while a face holds it), for the first round's live copy before that build.
class FreshMesh {
 public:
  // In `loops`' chunks (relaxed stores: chunks mark shared vertices alike).
  FreshMesh(const Mesh& mesh, ChunkedLoops& loops) : mesh_(mesh) {
    resize_touched(held_, mesh.positions.size(), loops, uint8_t(0));
    loops.run(mesh.faces.size(), [&](size_t begin, size_t end) {
      for (size_t f = begin; f < end; ++f)
        for (VertexId v : mesh.faces[f])
          std::atomic_ref<uint8_t>(held_[v]).store(1, std::memory_order_relaxed);
    });
  }
  size_t vertex_capacity() const { return mesh_.positions.size(); }
  size_t face_capacity() const { return mesh_.faces.size(); }
  bool vertex_alive(VertexId v) const { return held_[v]; }
  bool face_alive(FaceId) const { return true; }
  const Vec3& position(VertexId v) const { return mesh_.positions[v]; }
  const Triangle& face(FaceId f) const { return mesh_.faces[f]; }
  size_t live_vertices() const { return size_t(std::count(held_.begin(), held_.end(), 1)); }

 private:
  const Mesh& mesh_;
  std::vector<uint8_t> held_;
};

// In `loops`' chunks: the live vertices numbered per range (a group's first live copy numbers
// it), then the others of a group given its number, then the live faces. `Source`: a
// CollapseMesh, or a FreshMesh (the copy a CollapseMesh just built from it would give).
template <class Source>
LiveCopy live_copy(const Source& mesh, const CopyGroups& groups, ChunkedLoops& loops) {
  // The live vertex whose number v takes: itself, or its group's first live copy.
  auto numbered_as = [&](VertexId v) {
    if (!groups.is_copy(v)) return v;
    const auto copies = groups.of(groups.group[v]);
    return *std::find_if(copies.begin(), copies.end(),
                         [&](VertexId c) { return mesh.vertex_alive(c); });
  };
  const size_t capacity = mesh.vertex_capacity();
  KeptItems vertices = number_kept(loops, capacity, [&](size_t v) {
    return mesh.vertex_alive(VertexId(v)) && numbered_as(VertexId(v)) == v;
  });
  LiveCopy out;
  out.compact = std::move(vertices.new_id);
  resize_touched(out.mesh.positions, vertices.old_id.size(), loops);
  loops.run(vertices.old_id.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) out.mesh.positions[i] = mesh.position(vertices.old_id[i]);
  });
  if (!groups.empty())  // (each range writes only its later copies, reads only first ones)
    loops.run(capacity, [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v)
        if (out.compact[v] == kNoId && mesh.vertex_alive(VertexId(v)))
          out.compact[v] = out.compact[numbered_as(VertexId(v))];
    });
  const std::vector<uint32_t> faces =
      kept_items(loops, mesh.face_capacity(), [&](size_t f) { return mesh.face_alive(FaceId(f)); });
  resize_touched(out.mesh.faces, faces.size(), loops);
  loops.run(faces.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const Triangle& t = mesh.face(faces[i]);
      out.mesh.faces[i] = {out.compact[t[0]], out.compact[t[1]], out.compact[t[2]]};
    }
  });
  return out;
}

// Per vertex of the mesh a live copy was made from, its subset in a partition of the copy (0
// for vertices dead at the copy), in `loops`' chunks.
std::vector<uint32_t> subsets_of_copied(const LiveCopy& live, const Partition& partition,
                                        ChunkedLoops& loops) {
  std::vector<uint32_t> vertex_subset;
  resize_touched(vertex_subset, live.compact.size(), loops);
  loops.run(live.compact.size(), [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v)
      vertex_subset[v] = live.compact[v] != kNoId ? partition.vertex_subset[live.compact[v]] : 0;
  });
  return vertex_subset;
}

// Partitions a live copy into p subsets (subsets_of_copied), in options.loops' chunks.
std::vector<uint32_t> partition_copy(const LiveCopy& live, uint32_t p,
                                     const PartitionOptions& options) {
  ChunkedLoops one_thread;
  return subsets_of_copied(live, partition_mesh(live.mesh, p, options),
                           options.loops ? *options.loops : one_thread);
}

std::vector<uint32_t> partition_live(const CollapseMesh& mesh, const CopyGroups& groups, uint32_t p,
                                     const PartitionOptions& options) {
  ChunkedLoops one_thread;
  return partition_copy(live_copy(mesh, groups, options.loops ? *options.loops : one_thread), p,
                        options);
}

// Runs `work` on this thread and each of `sides` beside it, each on a thread of its own when
// the build may use more than one (one after the other otherwise). No side may touch what
// `work` or another side does.
struct Beside {
  double work_seconds = 0;
  std::vector<double> side_seconds;
  double side_cpu_elsewhere = 0;  // the sides' CPU when they ran on other threads
};
Beside run_beside(unsigned threads, const std::function<void()>& work,
                  const std::vector<std::function<void()>>& sides) {
  Beside out;
  out.side_seconds.assign(sides.size(), 0);
  auto timed_side = [&](size_t i) {
    const auto ts = std::chrono::steady_clock::now();
    const double cpu = thread_cpu_seconds();
    sides[i]();
    out.side_seconds[i] = seconds_since(ts);
    return thread_cpu_seconds() - cpu;
  };
  std::vector<std::future<double>> beside;
  if (pool_threads(threads, 2) >= 2)
    for (size_t i = 0; i < sides.size(); ++i)
      beside.push_back(std::async(std::launch::async, timed_side, i));
  const auto tw = std::chrono::steady_clock::now();
  try {
    work();
  } catch (...) {
    for (std::future<double>& f : beside) f.wait();
    throw;
  }
  out.work_seconds = seconds_since(tw);
  if (beside.empty()) {
    for (size_t i = 0; i < sides.size(); ++i) timed_side(i);
  } else {
    std::exception_ptr error;
    for (std::future<double>& f : beside) try {
        out.side_cpu_elsewhere += f.get();
      } catch (...) {
        if (!error) error = std::current_exception();
      }
    if (error) std::rethrow_exception(error);
  }
  return out;
}

// Whether a partition drawn on the mesh as the last round found it keeps that round's borders:
// more than half of the last round's bound vertices still alive are bound again. The greedy
// partitioner is deterministic from its start vertex, the seed's pick among a few vertices of
// least degree: two seeds can pick the same one and draw the same partition of the same mesh,
// and a round on it would leave the last round's borders as they were, unmended. Different
// partitions bind 1-13% of those vertices again.
// `bound`: the partition's bound vertices, found here.
bool repeats_borders(const CollapseMesh& mesh, const std::vector<uint32_t>& vertex_subset,
                     const std::vector<uint8_t>& bound_before, std::vector<uint8_t>& bound,
                     ChunkedLoops& loops) {
  bound = bound_vertices(mesh, vertex_subset, &loops);
  size_t before = 0, again = 0;
  for (VertexId v = 0; v < bound_before.size() && v < bound.size(); ++v)
    if (bound_before[v] && mesh.vertex_alive(v)) {
      ++before;
      again += bound[v];
    }
  spdlog::debug("the partition drawn ahead binds {} of the last round's {} bound vertices again",
                again, before);
  if (2 * again > before) {
    bound.clear();
    return true;
  }
  return false;
}

// The subsets of a round starting at `faces` (ParallelOptions::min_subset_faces); below 2 (with
// p >= 2), no round.
uint32_t round_subsets(const ParallelOptions& parallel, uint64_t faces) {
  if (parallel.min_subset_faces == 0 || parallel.subsets < 2) return parallel.subsets;
  return uint32_t(std::min<uint64_t>(parallel.subsets, faces / parallel.min_subset_faces));
}

void check_parallel_options(const ParallelOptions& parallel, size_t vertices) {
  if (parallel.subsets < 1 || parallel.subsets > kMaxPartitionSubsets)
    throw_invalid("the subset count p must be in [1, 256], got " +
                  std::to_string(parallel.subsets));
  if (parallel.subsets > vertices)
    throw_invalid("the subset count p = " + std::to_string(parallel.subsets) +
                  " exceeds the vertex count " + std::to_string(vertices));
  if (parallel.rounds > 64)
    throw_invalid("parallel rounds must be in [1, 64] (0: by p), got " +
                  std::to_string(parallel.rounds));
  if (!(parallel.border_excess >= 0 && parallel.border_excess <= 0.5))
    throw_invalid("the border excess must be in [0, 0.5] (0: geometric rounds only), got " +
                  number_text(parallel.border_excess));
  if (!(parallel.handover_ratio > 0 && parallel.handover_ratio <= 1))
    throw_invalid("the handover ratio must be in (0, 1], got " +
                  number_text(parallel.handover_ratio));
}

// The partitioner's seed of a round. It picks the start vertex as the (seed mod count)-th
// vertex of least degree in id order: consecutive seeds pick neighbouring ids, often close on
// the surface, and nearly the same partition, whose borders would stay where they were. A
// mixed seed starts each round somewhere else.
uint64_t round_seed(uint64_t seed, uint32_t round) {
  if (round == 0) return seed;
  SplitMix64 mix(seed + round);
  return mix.next() >> 1;
}

// The band pass's priority: the master's metric, restricted to edges with a lagging end (bound
// in this round and the one before, so not moved by either: where two cuts cross, around it
// faces may remain from two rounds ago) and a cost of at most `ceiling`; an edge above it is
// left alone until its star changes. A collapse's ends no longer lag.
class BandPriority : public PriorityWrapper {
 public:
  BandPriority(PriorityModule& inner, std::vector<uint8_t> lagging, double ceiling)
      : PriorityWrapper(inner), lagging_(std::move(lagging)), ceiling_(ceiling) {}
  void initialize(const CollapseMesh&) override {}
  // (its ceiling may refuse a collapse's cost above it whose queue key, a lower bound, is not)
  bool placed_when_queued_is_placed() const override { return false; }
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    if (!lagging_[a] && !lagging_[b]) return false;
    return inner_.evaluate(mesh, a, b, out, costing) && out.cost <= ceiling_;
  }
  void evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                     Costing costing) override {
    for (const size_t i : evaluate_picked(mesh, edges, costing, [&](const EdgeCosting& e) {
           return lagging_[e.a] || lagging_[e.b];
         }))
      edges[i].placed = edges[i].placed && edges[i].candidate.cost <= ceiling_;
  }
  bool evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                     CollapseCandidate& out, Costing costing) override {
    if (!lagging_[vs] && !lagging_[vt]) return false;
    return inner_.evaluate_seam(mesh, vs, vt, at, out, costing) && out.cost <= ceiling_;
  }
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                 const EdgeFaces& edge) override {
    lagging_[done.vs] = lagging_[done.vt] = 0;
    inner_.collapsed(mesh, done, edge);
  }

 private:
  std::vector<uint8_t> lagging_;
  double ceiling_;
};

// The master's current keys of the job's edges with two free ends (`free`: free_vertices of
// the job; the only edges it costs), in its local ids, sorted. Const reads of `memo`: jobs may take
// theirs concurrently.
std::vector<EdgeKey> keys_of_job(const KeyMemo& memo, const SubsetJob& job,
                                 const std::vector<uint8_t>& free) {
  const std::vector<VertexId>& global = job.global_vertex;
  std::vector<EdgeKey> keys;
  for (VertexId a = 0; a < global.size(); ++a) {
    if (!free[a]) continue;
    memo.for_each_current_at(global[a], [&](const EdgeKey& k) {
      const auto it = std::lower_bound(global.begin() + a + 1, global.end(), k.b);
      if (it == global.end() || *it != k.b) return;
      const auto b = VertexId(it - global.begin());
      if (free[b]) keys.push_back({a, b, k.cost});
    });
  }
  sort_keys(keys);
  return keys;
}

// The master's deferred edges (global ids, sorted) with two free ends in the job, in its
// local ids, sorted, but those `keys` (the job's, sorted) answer: a costing known is better
// than a deferral. Const reads: jobs may take theirs concurrently.
std::vector<DeferredEdge> deferred_of_job(const std::vector<DeferredEdge>& deferred,
                                          const SubsetJob& job, const std::vector<uint8_t>& free,
                                          const std::vector<EdgeKey>& keys) {
  const std::vector<VertexId>& global = job.global_vertex;
  std::vector<DeferredEdge> out;
  if (deferred.empty()) return out;
  for (VertexId a = 0; a < global.size(); ++a) {
    if (!free[a]) continue;
    auto d = std::lower_bound(deferred.begin(), deferred.end(), global[a],
                              [](const DeferredEdge& e, VertexId v) { return e.a < v; });
    for (; d != deferred.end() && d->a == global[a]; ++d) {
      const auto it = std::lower_bound(global.begin() + a + 1, global.end(), d->b);
      if (it == global.end() || *it != d->b) continue;
      const auto b = VertexId(it - global.begin());
      if (free[b] && !has_key(keys, a, b)) out.push_back({a, b, d->key});
    }
  }
  return out;  // sorted: by a, then by b (global order is local order)
}

// Drops the deferred edges with an end that one of `lists`' collapses changed (its vs or vt:
// the deferral no longer stands for the edge as it is).
void drop_changed(std::vector<DeferredEdge>& deferred, size_t vertex_capacity,
                  const std::vector<const std::vector<CollapseRecord>*>& lists) {
  if (deferred.empty()) return;
  std::vector<uint8_t> changed(vertex_capacity, 0);
  for (const std::vector<CollapseRecord>* list : lists)
    for (const CollapseRecord& r : *list) changed[r.vs] = changed[r.vt] = 1;
  std::erase_if(deferred, [&](const DeferredEdge& d) { return changed[d.a] || changed[d.b]; });
}

// `requested` with a kByMetric floor set for `master`'s metric.
ParallelOptions with_metric_floor(ParallelOptions requested, const PriorityModule& master) {
  if (requested.min_subset_faces == kByMetric)
    requested.min_subset_faces = subset_faces_by_metric(master.costly());
  return requested;
}

// A round shortened by its border band still removes this fraction of its faces: on a small
// mesh cut in many subsets the band is a fifth of the faces or more, and the bound alone would
// ask for rounds of a few percent (fandisk at p = 16: 13 rounds to the handover).
constexpr double kMinRoundRemoval = 0.15;

// The face count a round from `faces` may end at so that its border band of `border` faces
// holds back at most `excess` x that count (ParallelOptions::border_excess); 0 without a bound.
uint64_t border_bounded_goal(uint64_t faces, uint64_t border, double excess) {
  if (excess <= 0 || border == 0 || faces == 0) return 0;
  const double band = double(border) / double(faces);
  const double ratio = std::min(1.0 - kMinRoundRemoval, 1.0 / (1.0 + excess / band));
  return uint64_t(std::llround(ratio * double(faces)));
}

}  // namespace

// A live copy of the mesh and its partition graph, for several partitions of the same mesh.
struct ParallelBuilder::LiveGraph {
  template <class Source>
  LiveGraph(const Source& mesh, const CopyGroups& groups, ChunkedLoops& loops)
      : live(live_copy(mesh, groups, loops)), graph(live.mesh, Balance::kFaces, &loops) {}
  // Per vertex of the mesh, its subset (subsets_of_copied).
  std::vector<uint32_t> draw(uint32_t p, const PartitionOptions& options) const {
    ChunkedLoops one_thread;
    return subsets_of_copied(live, graph.draw(p, options),
                             options.loops ? *options.loops : one_thread);
  }
  LiveCopy live;
  PartitionGraph graph;
};

ParallelBuilder::ParallelBuilder(const RepairedMesh& repaired, const SimplifyOptions& options,
                                 const ParallelOptions& requested, ParallelStats* stats,
                                 const ProgressCallback& progress, const CancelToken* cancel,
                                 SubsetRunner* runner, const ParallelEvents& events)
    : repaired_(repaired),
      mesh_(repaired.mesh),
      options_(options),
      requested_(requested),
      st_(stats ? *stats : local_stats_),
      progress_(progress),
      cancel_(cancel),
      pool_(requested.threads, requested.subsets, requested.team_min_points),
      master_loops_(requested.subsets, requested.threads),
      runner_(runner ? runner : &pool_),
      events_(events),
      start_(std::chrono::steady_clock::now()),
      master_cpu_start_(thread_cpu_seconds()) {
  check_simplify_options(options);
  check_parallel_options(requested, mesh_.vertex_count());
  st_ = {};
  st_.subsets = requested.subsets;
  rounds_ = scheduled_rounds(requested);
  st_.rounds = rounds_;
  st_.threads = pool_threads(requested.threads, requested.subsets);
  input_faces_ = mesh_.face_count();
  target_ = target_face_count(input_faces_, options);
  handover_ = std::max<uint64_t>(
      target_, uint64_t(std::llround(requested.handover_ratio * double(input_faces_))));
  on_membrane_ = membrane_vertices(repaired);
  if (!options.free_copies) copy_groups_ = copy_groups(repaired, on_membrane_);
  locked_ = locked_vertices(copy_groups_, mesh_.vertex_count());
  defer_line_ = defer_recosting_line(input_faces_);
  free_line_ = free_placement_line_of(options_, input_faces_);
  // After two scheduled rounds (a ratio of 0.32 at the default handover), an extra round at
  // the scheduled ratio would need 3.2 x the floor per subset to start, and mid-sized meshes
  // at p = 2 would get none (a longer sequential final pass).
  const double handover_ratio = double(handover_) / double(input_faces_);
  step_ = std::max(std::pow(handover_ratio, 1.0 / double(rounds_)),
                   std::pow(handover_ratio, 1.0 / 3.0));
  scheduled_left_ = rounds_;
}

void ParallelBuilder::set_up() {
  // The passes over the whole mesh run in p chunks: with a core per subset (the critical
  // path's assumption) each pass takes its slowest chunk.
  ChunkedLoops loops(requested_.subsets, requested_.threads);
  const LoopClock start_clock(loops);
  master_ = make_priority_module(options_, mesh_, locked_);
  if (master_->costly() && requested_.team_min_points > 0) {
    team_.emplace(requested_.subsets, requested_.threads, requested_.team_min_points);
    master_->use_team(&*team_);
  }
  parallel_ = with_metric_floor(requested_, *master_);
  const double start_seconds = start_clock.critical_seconds();
  // The first round's partition needs the repaired mesh only: it is drawn beside the whole
  // mesh's build and the master's initialisation, on the mesh as that build shows it
  // (first_round_ repeats the round's plan there).
  const uint32_t first_subsets = round_subsets(parallel_, mesh_.face_count());
  const bool may_partition = first_subsets >= std::min(2u, parallel_.subsets) &&
                             mesh_.vertex_count() >= 4 * size_t(first_subsets) &&
                             mesh_.face_count() > handover_;
  bool first_round = false;
  auto partition_first_round = [&] {
    const LoopClock clock(master_loops_);
    const FreshMesh fresh(mesh_, master_loops_);
    first_round = fresh.live_vertices() >= 4 * size_t(first_subsets);
    if (!first_round) return;
    auto source = std::make_shared<const LiveGraph>(fresh, copy_groups_, master_loops_);
    PartitionOptions partition_options;
    partition_options.seed = round_seed(options_.seed, 0);
    partition_options.loops = &master_loops_;
    first_partition_ = source->draw(first_subsets, partition_options);
    first_partition_seconds_ = clock.critical_seconds();
    if (parallel_.early_partition) draw_round_one(std::move(source), first_subsets, start_seconds);
  };
  double build_seconds = 0, initialize_seconds = 0;
  run_beside(
      parallel_.threads,
      [&] {
        const LoopClock build_clock(loops);
        whole_.emplace(mesh_, loops);
        build_seconds = build_clock.critical_seconds();
        const LoopClock clock(loops);
        master_->initialize_in_chunks(*whole_, loops);
        initialize_seconds = clock.critical_seconds();
      },
      may_partition ? std::vector<std::function<void()>>{partition_first_round}
                    : std::vector<std::function<void()>>{});
  first_round_ = first_round;
  partition_beside_seconds_ = build_seconds + initialize_seconds;
  const LoopClock after_clock(loops);
  keys_.emplace(*master_, whole_->vertex_capacity());
  carry_keys_ = parallel_.carry_keys && master_->costly();
  carry_deferred_ = carry_keys_ && parallel_.carry_deferred;
  master_queue_ = carry_keys_ ? static_cast<PriorityModule*>(&*keys_) : master_.get();
  subset_options_ = subset_options_of(options_, mesh_);
  records_.reserve(whole_->live_vertices());
  // The set-up's own time, its loops at their critical path; the first partition is round 0's
  // (which the critical path counts only where it outlasts the build and the initialisation:
  // RoundStats::partition_overlap_seconds).
  st_.setup_seconds = start_seconds + partition_beside_seconds_ + after_clock.critical_seconds();
}

std::shared_ptr<const std::vector<uint32_t>> ParallelBuilder::whole_components() {
  if (!components_) {
    auto found = std::make_shared<std::vector<uint32_t>>();
    connected_components(*whole_, *found);
    components_ = std::move(found);
  }
  return components_;
}

void ParallelBuilder::append_pending() {
  append_merge_order(pending_lists_, records_);
  for (std::vector<CollapseRecord>& list : pending_lists_) keep_list(std::move(list));
  pending_lists_.clear();
}

void ParallelBuilder::append_list(std::vector<CollapseRecord> list) {
  for (const CollapseRecord& r : list) records_.push_back(&r);
  keep_list(std::move(list));
}

void ParallelBuilder::keep_list(std::vector<CollapseRecord> list) {
  // A simplifier reserves a record per vertex and makes fewer; where the allocator reused
  // memory for the reserve, its unused pages are resident.
  release_unused_capacity(list);
  record_lists_.push_back(std::move(list));
}

ParallelBuilder::RoundPlan ParallelBuilder::plan_round(uint64_t faces, size_t vertices,
                                                       uint32_t scheduled_rounds_left,
                                                       const RoundStats* last) const {
  RoundPlan plan;
  plan.subsets = round_subsets(parallel_, faces);
  if (plan.subsets < std::min(2u, parallel_.subsets)) return plan;
  if (vertices < 4 * size_t(plan.subsets)) return plan;
  // A round whose jobs removed less than a tenth of what they were asked ends the rounds:
  // the mesh is stuck (locked copies of non-manifold vertices, or collapses only the final
  // pass takes, above every ceiling), and rounds on new partitions would
  // extract, cost and merge it again for nothing (chair-dupfaces-13k, whose every vertex is
  // locked: three rounds of no collapse took 6-9x the sequential build's CPU).
  if (last && last->asked_faces > 0 &&
      double(last->faces_before - last->faces_after) < 0.1 * double(last->asked_faces))
    return plan;
  plan.scheduled = scheduled_rounds_left > 0;
  if (plan.scheduled) {
    if (faces <= handover_) return plan;
    // Geometric steps from the present face count to the handover.
    plan.goal =
        uint64_t(std::llround(double(faces) * std::pow(double(handover_) / double(faces),
                                                       1.0 / double(scheduled_rounds_left))));
  } else {
    // An extra round, if the last one's jobs did what they were asked (a mesh whose locked
    // parts stop it short gains nothing from more) and the subsets stay large enough that
    // their borders do not decide the order. A round that did only half of it stopped at its
    // cost ceiling: the rest is costlier, its order matters more, so the next round's subsets
    // must be larger (2.5 x the floor; decisions/notebook-2026-11.md, "Extra rounds after a
    // short round").
    if (parallel_.extra_round_subset_faces == 0 || !last) return plan;
    const double done = double(last->faces_before) - double(last->faces_after);
    const double asked = double(last->asked_faces);
    if (!(done >= 0.5 * asked)) return plan;
    const uint64_t floor = done >= 0.9 * asked ? parallel_.extra_round_subset_faces
                                               : parallel_.extra_round_subset_faces * 5 / 2;
    // Even geometric steps to the target, as many as the target is steps away, rounded:
    // stepping by `step_` and stopping at the target can end on a sliver of a round (asked
    // only for what the last round's border kept).
    if (step_ >= 1) return plan;
    const double to_target = std::max(1.0, double(target_)) / double(faces);
    const double steps = std::max(1.0, std::round(std::log(to_target) / std::log(step_)));
    plan.goal = std::max<uint64_t>(
        target_, uint64_t(std::llround(double(faces) * std::pow(to_target, 1.0 / steps))));
    // Like a round bounded by its border band, an extra round removes at least 15% of its
    // faces (or a step, if many rounds make that gentler); the final pass does less.
    const double least = std::min(kMinRoundRemoval, 1 - step_) * double(faces);
    if (double(faces) - double(plan.goal) < least) return plan;
    // Narrower rounds once p subsets would leave fewer faces each than the floor: the mesh
    // keeps shrinking in parallel, and the sequential final pass stays short at any p.
    plan.subsets = uint32_t(std::min<uint64_t>(plan.subsets, plan.goal / floor));
    if (plan.subsets < 2) return plan;
  }
  plan.go = true;
  return plan;
}

bool ParallelBuilder::counts(const RoundStats& r) {
  return !r.border_limited || 2 * (r.faces_before - r.faces_after) < r.asked_faces;
}

void ParallelBuilder::forgo_foreseen() {
  if (foreseen_.beside_band && !st_.round_stats.empty())
    st_.round_stats.back().append_beyond_band_seconds =
        std::max(0.0, foreseen_.append_seconds - foreseen_.band_seconds);
  foreseen_ = Foreseen{};
}

bool ParallelBuilder::round() {
  release_free_memory();  // what the last round's jobs freed on the pool's threads
  if (round_index_ >= 64) {
    forgo_foreseen();  // (the rounds' limit)
    return false;
  }
  CollapseMesh& whole = *whole_;
  Round r;
  r.rs.round = round_index_;
  r.rs.faces_before = whole.live_faces();
  const RoundPlan plan = plan_round(r.rs.faces_before, whole.live_vertices(), scheduled_left_,
                                    st_.round_stats.empty() ? nullptr : &st_.round_stats.back());
  if (!plan.go) {
    forgo_foreseen();
    return false;
  }
  r.subsets = plan.subsets;
  r.scheduled = plan.scheduled;
  r.rs.goal_faces = plan.goal;
  partition(r);
  bound_goal_by_border(r);
  extract_jobs(r);
  run_subsets(r);
  merge(r);
  band_pass(r);
  finish_round(r);
  ++round_index_;
  return true;
}

// A new partition of the current mesh: the previous round's borders, whose vertices could not
// move, are inside subsets now.
void ParallelBuilder::partition(Round& r) {
  RoundStats& rs = r.rs;
  const uint32_t round = rs.round;
  if (round == 1 && round_one_.valid()) take_round_one();
  const LoopClock check_clock(master_loops_);
  // Round 1's partition drawn beside round 0, unless it keeps round 0's borders.
  const bool early_drawn =
      foreseen_.drawn && !foreseen_.beside_band && foreseen_.subsets == r.subsets;
  const bool early_taken =
      early_drawn && !repeats_borders(*whole_, foreseen_.vertex_subset, bound_before_, early_bound_,
                                      master_loops_);
  const double early_check_seconds = check_clock.critical_seconds();
  if (round == 0 && first_round_) {
    // Drawn during the setup (whose first_round_ repeats the plan's checks).
    r.vertex_subset = std::move(first_partition_);
    rs.partition_seconds = first_partition_seconds_;
    rs.partition_overlap_seconds = std::min(first_partition_seconds_, partition_beside_seconds_);
  } else if (early_taken) {
    // Drawn beside round 0: the critical path counts what of it outlasted round 0, and its
    // check. The previous round's records are appended beside this round's jobs.
    r.vertex_subset = std::move(foreseen_.vertex_subset);
    rs.partition_foreseen = true;
    rs.partition_seconds = foreseen_.partition_seconds + early_check_seconds;
    rs.partition_overlap_seconds = std::min(foreseen_.partition_seconds, foreseen_.beside_seconds);
    r.append_beside_jobs = true;
  } else if (foreseen_.drawn && foreseen_.beside_band && foreseen_.subsets == r.subsets) {
    // Drawn beside the last band pass, the previous round's records appended beside it too:
    // the critical path counts what of them outlasted the band pass.
    r.vertex_subset = std::move(foreseen_.vertex_subset);
    rs.partition_foreseen = true;
    rs.partition_seconds = foreseen_.copy_seconds + foreseen_.partition_seconds;
    rs.append_seconds = foreseen_.append_seconds;
    const double longest =
        std::max({foreseen_.partition_seconds, foreseen_.append_seconds, foreseen_.band_seconds});
    rs.partition_overlap_seconds =
        foreseen_.partition_seconds + foreseen_.append_seconds - (longest - foreseen_.band_seconds);
  } else {
    if (early_drawn)
      spdlog::debug(
          "parallel round {}: the partition drawn beside the last round's jobs keeps "
          "its borders; drawn anew",
          round);
    forgo_foreseen();
    PartitionOptions partition_options;
    partition_options.seed = round_seed(options_.seed, round);
    partition_options.loops = &master_loops_;
    double partition_seconds = 0;
    const Beside timed = run_beside(parallel_.threads,
                                    [&] {
                                      const LoopClock clock(master_loops_);
                                      r.vertex_subset = partition_live(
                                          *whole_, copy_groups_, r.subsets, partition_options);
                                      partition_seconds = clock.critical_seconds();
                                    },
                                    {[this] { append_pending(); }});
    rs.partition_seconds = partition_seconds + early_check_seconds;
    rs.append_seconds = timed.side_seconds[0];
    rs.partition_overlap_seconds = std::min(partition_seconds, timed.side_seconds[0]);
    subsets_cpu_ += timed.side_cpu_elsewhere;
  }
  foreseen_ = Foreseen{};
  if (events_.partitioned) events_.partitioned(round, r.subsets, rs.faces_before);
}

// The partition's border (O(faces) in the master's chunks, counted with the partition), and the
// goal a scheduled round may reach with it (ParallelOptions::border_excess).
void ParallelBuilder::bound_goal_by_border(Round& r) {
  RoundStats& rs = r.rs;
  const LoopClock clock(master_loops_);
  r.bound = early_bound_.empty() ? bound_vertices(*whole_, r.vertex_subset, &master_loops_)
                                 : std::move(early_bound_);
  early_bound_.clear();
  rs.border_faces = border_faces(*whole_, r.bound, &master_loops_);
  rs.partition_seconds += clock.critical_seconds();
  if (r.scheduled && parallel_.border_excess > 0) {
    const uint64_t bounded =
        border_bounded_goal(rs.faces_before, rs.border_faces, parallel_.border_excess);
    if (bounded > rs.goal_faces) {
      rs.goal_faces = bounded;
      rs.border_limited = true;
    }
  }
}

// The jobs: which vertices each subset owns (sequential, O(vertices)), the water level
// (sequential, on the master), then each job's mesh and the master's state over it, one job per
// pool task (const reads of the whole mesh and the master: concurrently). With a core per
// subset, only the slowest job's extraction is on the critical path.
void ParallelBuilder::extract_jobs(Round& r) {
  RoundStats& rs = r.rs;
  const CollapseMesh& whole = *whole_;
  const uint32_t subsets = r.subsets;
  const auto t = std::chrono::steady_clock::now();
  const LoopClock owned_clock(master_loops_);
  const std::vector<std::vector<VertexId>> owned =
      owned_vertices(whole, r.vertex_subset, subsets, master_loops_);
  const bool sample = parallel_.water_level_factor > 0 || parallel_.cost_shares;
  std::vector<SubsetJob>& jobs = r.jobs;
  jobs.resize(subsets);
  std::vector<uint64_t> removable(subsets, 0);
  std::vector<SubsetSample> samples(sample ? subsets : 0);
  // A cheap metric's sample is costed by the master (sample_on_master): in the tasks, each
  // through a costing view of the master (the same costs), unless the master has none or the
  // mesh has copy groups (a seam's costing walks the whole mesh's marks); else the tasks only
  // pick its edges. A costly one's is costed side by side in the tasks, by their jobs' states.
  const bool sample_in_tasks = sample && master_->costly();
  const bool master_in_tasks =
      sample && !sample_in_tasks && copy_groups_.empty() && master_->costing_view() != nullptr;
  std::vector<SampledEdges> sampled(sample && !sample_in_tasks && !master_in_tasks ? subsets : 0);
  // A job run in this process takes the mesh and metric its sample was costed on (the job's
  // state then goes: the metric holds it).
  const bool jobs_here = runner_ == &pool_;
  std::vector<PreparedSubset> prepared(sample_in_tasks && jobs_here ? subsets : 0);
  // Such a job's metric reads its state straight from the master where it can, without a
  // state's copy of its points in between (imports_from_master).
  const bool state_needed = job_state_needed(*master_, rs.round);
  // Per face, the subset whose job owns its three corners: the only state that may list it.
  face_subset_.assign(whole.face_capacity(), kNoId);
  // The master's own steps, before the jobs' extraction and after it, are on the critical path.
  double sequential_extract = owned_clock.critical_seconds();
  std::vector<double> job_cpu(jobs.size(), 0), sample_cpu(samples.size(), 0);
  // A round of fewer jobs than p: each task writes and imports its job's state on the cores the
  // round leaves, as its job's team will (ThreadPoolRunner).
  const JobTeam task_team = team_of_round(subsets, parallel_.subsets, parallel_.threads, 0);
  run_jobs(jobs.size(), parallel_.threads, [&](size_t i) {
    const double cpu = thread_cpu_seconds();
    ChunkedLoops state_loops = state_loops_of(task_team);
    // The jobs' meshes carry the input's wedge values; the metric's current ones
    // (E_scalar) travel in the state.
    jobs[i] = extract_subset(whole, mesh_.layout, mesh_.wedge_values, mesh_.positions_are_float,
                             locked_, r.vertex_subset, owned[i], uint32_t(i), rs.round,
                             subset_options_, &copy_groups_);
    if (state_needed && !prepared.empty() && imports_from_master(*master_, jobs[i]))
      prepared[i] = prepare_subset(jobs[i], &state_loops, master_.get());
    else if (state_needed)
      jobs[i].state = export_job_state(*master_, jobs[i], &state_loops);
    for (FaceId f = 0; f < jobs[i].mesh.face_count(); ++f) {
      const Triangle& c = jobs[i].mesh.faces[f];
      if (jobs[i].owned[c[0]] && jobs[i].owned[c[1]] && jobs[i].owned[c[2]])
        face_subset_[jobs[i].global_face[f]] = uint32_t(i);
    }
    const std::vector<uint8_t> free = free_vertices(jobs[i].mesh, jobs[i].owned);
    removable[i] = removable_faces(jobs[i].mesh, free);
    if (carry_keys_) jobs[i].keys = keys_of_job(*keys_, jobs[i], free);
    if (sample) {
      const double sample_start = thread_cpu_seconds();
      if (sample_in_tasks) {
        samples[i] = sample_subset(jobs[i], free, carry_keys_, jobs[i].keys,
                                   prepared.empty() ? nullptr : &prepared[i], &state_loops);
        if (!prepared.empty() && prepared[i].metric) jobs[i].state = MetricState{};
      } else if (master_in_tasks) {
        const std::unique_ptr<PriorityModule> view = master_->costing_view();
        Simplifier master_costs(*whole_, *view, {});
        samples[i] = sample_on_master(jobs[i], sampled_edges(jobs[i], free), master_costs, *view);
      } else {
        sampled[i] = sampled_edges(jobs[i], free);
      }
      sample_cpu[i] = thread_cpu_seconds() - sample_start;
    }
    if (carry_deferred_) jobs[i].deferred = deferred_of_job(deferred_, jobs[i], free, jobs[i].keys);
    // (its state's loops at their slowest chunk, as with a core per chunk)
    job_cpu[i] =
        thread_cpu_seconds() - cpu - (state_loops.seconds() - state_loops.critical_seconds());
  });
  const auto after_jobs = std::chrono::steady_clock::now();
  // The water level and the shares (sequential: a sort of the samples).
  RoundCosts round_costs;
  if (sample) {
    if (!sample_in_tasks && !master_in_tasks) {
      const double sample_start = thread_cpu_seconds();
      Simplifier master_costs(*whole_, *master_, {});
      if (!copy_groups_.empty()) master_costs.join_copies(&copy_groups_);
      for (size_t i = 0; i < jobs.size(); ++i)
        samples[i] = sample_on_master(jobs[i], sampled[i], master_costs, *master_);
      rs.share_seconds += thread_cpu_seconds() - sample_start;
      for (const SubsetSample& s : samples) master_sample_costings_ += s.costings;
    }
    round_costs =
        round_costs_of(samples, rs.faces_before - rs.goal_faces, parallel_.water_level_factor);
    if (!parallel_.cost_shares) round_costs.cheap_fraction.clear();
    if (parallel_.water_level_factor > 0) rs.water_level = round_costs.ceiling;
    for (double c : sample_cpu) rs.share_seconds += c;
    for (const SubsetSample& s : samples) sample_costings_ += s.costings;
  }
  rs.asked_faces =
      set_targets(jobs, removable, rs.faces_before, rs.goal_faces, round_costs.cheap_fraction);
  // Deferred re-costing as the sequential build has it at these face counts: in every round
  // that ends at the line or above (by default the last scheduled round ends at it).
  for (SubsetJob& job : jobs)
    job.options.defer_recosting = options_.defer_recosting && rs.goal_faces >= defer_line_;
  // The quadric's placement as the master's at the round's start, where it costed the round's
  // sample: free while the sequential build's would be.
  for (SubsetJob& job : jobs) job.options.free_placement = rs.faces_before > free_line_;
  if (parallel_.water_level_factor > 0)
    for (SubsetJob& job : jobs)
      job.options.max_cost = job.options.max_cost > 0
                                 ? std::min(job.options.max_cost, rs.water_level)
                                 : rs.water_level;
  for (const SubsetJob& job : jobs) {
    rs.keys_carried += job.keys.size();
    rs.deferred_carried += job.deferred.size();
  }
  for (double c : job_cpu) {
    subsets_cpu_ += c;  // master work, on the pool's threads
    rs.slowest_extract_cpu_seconds = std::max(rs.slowest_extract_cpu_seconds, c);
  }
  sequential_extract += seconds_since(after_jobs);
  rs.extract_seconds = seconds_since(t);
  rs.extract_critical_seconds = sequential_extract + rs.slowest_extract_cpu_seconds;
  if (!prepared.empty()) pool_.take_prepared(std::move(prepared));
}

// Round 1's partition, on round 0's graph (the mesh as round 0 finds it: the whole mesh changes
// only at round 0's merge): on a thread of its own, beside round 0's extraction, jobs and
// merge, as drawn after the merge it would be all on the critical path. The price: its
// subsets, balanced for round 0's faces, hold round 1's a little unevenly (round 0's jobs stop
// at its water level). `start`: the critical path's seconds before round 0's partition.
void ParallelBuilder::draw_round_one(std::shared_ptr<const LiveGraph> source, uint32_t subsets,
                                     double start) {
  round_one_subsets_ = subsets;
  round_one_start_ = start + first_partition_seconds_;
  auto draw = [source = std::move(source), subsets, seed = round_seed(options_.seed, 1)]() mutable {
    const auto t = std::chrono::steady_clock::now();
    const double cpu = thread_cpu_seconds();
    PartitionOptions options;
    options.seed = seed;
    DrawnAhead drawn;
    drawn.vertex_subset = source->draw(subsets, options);
    source.reset();  // the graph's memory, back before round 0's jobs end
    drawn.seconds = seconds_since(t);
    drawn.cpu_seconds = thread_cpu_seconds() - cpu;
    return drawn;
  };
  round_one_elsewhere_ = pool_threads(parallel_.threads, 2) >= 2;
  if (round_one_elsewhere_) {
    round_one_ = std::async(std::launch::async, std::move(draw));
  } else {
    std::promise<DrawnAhead> now;
    round_one_ = now.get_future();
    try {
      now.set_value(draw());
    } catch (...) {
      now.set_exception(std::current_exception());
    }
  }
}

// Round 1's partition as foreseen_, beside what of the critical path ran from its start to
// round 1: the rest of the set-up and round 0.
void ParallelBuilder::take_round_one() {
  DrawnAhead drawn = round_one_.get();
  if (round_one_elsewhere_) subsets_cpu_ += drawn.cpu_seconds;
  foreseen_ = Foreseen{};
  foreseen_.drawn = true;
  foreseen_.subsets = round_one_subsets_;
  foreseen_.vertex_subset = std::move(drawn.vertex_subset);
  foreseen_.partition_seconds = drawn.seconds;
  const double round_one = st_.setup_seconds + round_critical_seconds(st_.round_stats.front());
  foreseen_.beside_seconds = std::max(0.0, round_one - round_one_start_);
}

// The jobs, on the runner.
void ParallelBuilder::run_subsets(Round& r) {
  RoundStats& rs = r.rs;
  // The master costs nothing while the jobs run: its caches make way for theirs.
  master_->release_caches();
  std::vector<std::function<void()>> beside_jobs;
  if (r.append_beside_jobs) beside_jobs.push_back([this] { append_pending(); });
  // The whole mesh's components, which the band passes and the final pass take (collapses
  // neither merge nor split them), found beside round 0's jobs: the mesh stands still.
  if (rs.round == 0 && !components_) beside_jobs.push_back([this] { whole_components(); });
  const Beside timed = run_beside(
      parallel_.threads, [&] { r.results = runner_->run(r.jobs, cancel_); }, beside_jobs);
  r.jobs.clear();
  rs.subsets_seconds = timed.work_seconds;
  if (r.append_beside_jobs) rs.append_seconds = timed.side_seconds.front();
  subsets_cpu_ += timed.side_cpu_elsewhere;
  if (cancel_) cancel_->check();
  if (r.results.size() != r.subsets)
    throw Error(ErrorCode::kInternal, "the subset runner returned " +
                                          std::to_string(r.results.size()) + " results for " +
                                          std::to_string(r.subsets) + " jobs");
}

// The subsets' records replay on the whole mesh, side by side (replay_subsets: by the subset
// rule they change disjoint parts of it, and the mesh ends as a merged replay leaves it);
// beside them, the jobs' states go into the master, and the round's water level and keys are
// taken from the records and results (take_results: the module, the memo's own lists, data
// the replay does not touch).
void ParallelBuilder::merge(Round& r) {
  RoundStats& rs = r.rs;
  const auto t = std::chrono::steady_clock::now();
  r.lists.reserve(r.results.size());
  for (SubsetResult& result : r.results) {
    rs.subsets.push_back({result.subset, result.faces, result.owned_faces, result.records.size(),
                          result.wall_seconds, result.cpu_seconds, result.stats.stop_reason});
    subsets_cpu_ += result.cpu_seconds + result.team_cpu_seconds;
    job_costings_ += result.costings;
    rs.slowest_subset_cpu_seconds =
        std::max(rs.slowest_subset_cpu_seconds, result.cpu_seconds - result.team_saved_seconds);
    r.lists.push_back(std::move(result.records));
    rs.keys_reused += result.keys_reused;
  }
  if (parallel_.replay_state) {
    // Tests only: the merged sequence drives the master's module, one collapse at a time
    // (merged from a copy: take_results reads the lists).
    std::vector<CollapseRecord> merged = merge_by_cost(r.lists);
    r.replay = replay_collapses(*whole_, merged, master_.get());
    take_results(r);
    append_list(std::move(merged));
  } else {
    const auto tr = std::chrono::steady_clock::now();
    double bookkeeping_seconds = 0;
    r.replay = replay_subsets(*whole_, r.lists, r.vertex_subset, parallel_.threads,
                              [&] { bookkeeping_seconds = take_results(r); });
    // With a core per subset (as the critical path assumes), the slowest subset's replay or
    // the bookkeeping, whichever is longer.
    rs.merge_overlap_seconds =
        std::max(0.0, seconds_since(tr) - std::max(r.replay.slowest_seconds, bookkeeping_seconds));
    // Into the PM's records at the next step (append_pending): each record moved once (a
    // merged list moved again took as long as the merge itself).
    pending_lists_ = std::move(r.lists);
  }
  rs.merge_seconds = seconds_since(t);
  // An append beside the jobs: the critical path counts what of it outlasted the slowest.
  if (r.append_beside_jobs)
    rs.partition_overlap_seconds += std::min(rs.append_seconds, rs.slowest_subset_cpu_seconds);
}

double ParallelBuilder::take_results(Round& r) {
  const auto tb = std::chrono::steady_clock::now();
  double import_saved = 0;  // what the imports side by side save with a core per state
  std::vector<const std::vector<CollapseRecord>*> changes;  // each job's records
  for (const std::vector<CollapseRecord>& list : r.lists) changes.push_back(&list);
  if (!parallel_.replay_state) {
    std::vector<const MetricState*> states;
    for (const SubsetResult& result : r.results) states.push_back(&result.state);
    const ImportTimes import = import_result_states(*master_, states, r.vertex_subset, face_subset_,
                                                    parallel_.threads, changes, parallel_.subsets);
    import_saved = std::max(0.0, import.seconds - import.critical_seconds);
  }
  std::vector<double> costs;
  for (const std::vector<CollapseRecord>& list : r.lists)
    for (const CollapseRecord& record : list) costs.push_back(record.cost);
  if (!costs.empty()) {
    const size_t k = costs.size() * 95 / 100;
    std::nth_element(costs.begin(), costs.begin() + ptrdiff_t(k), costs.end());
    r.ceiling = costs[k];
  }
  // The jobs' keys are current on the master (edge_keys.h). (The replay does not tell the
  // memo of its collapses: the keys stay current whichever runs first.)
  std::vector<EdgeKey> returned;
  if (carry_keys_)
    for (SubsetResult& result : r.results)
      returned.insert(returned.end(), result.keys.begin(), result.keys.end());
  if (carry_deferred_) {
    // The deferred edges of the jobs' free vertices are the jobs' to report (a job holds
    // them all in its queue); the others stand unless a collapse changed an end.
    drop_changed(deferred_, whole_->vertex_capacity(), changes);
    // A job reports again what it was given and left as it was: its report first, so
    // that the merge keeps it.
    std::vector<const std::vector<DeferredEdge>*> lists;
    for (SubsetResult& result : r.results) {
      check_deferred_edges(result.deferred, whole_->vertex_capacity());
      lists.push_back(&result.deferred);
    }
    lists.push_back(&deferred_);
    deferred_ = merge_unique_edges(lists, master_loops_);
  }
  keys_->reset(returned);
  return seconds_since(tb) - import_saved;
}

// The band pass, after every round but the first: what two rounds' borders both kept
// (vertices bound in both partitions, at the resolution of two rounds before) and is below the
// round's water level, sequentially on the whole mesh, cheapest first. (After the first round
// the next round's new partition takes its band in parallel.) Only those: a vertex no collapse
// has touched yet may just be inside a region a short round did not reach, which the next
// round takes in parallel. The next round's partition is drawn beside it, on a copy of the
// mesh as the band pass found it.
void ParallelBuilder::band_pass(Round& r) {
  RoundStats& rs = r.rs;
  CollapseMesh& whole = *whole_;
  const auto t = std::chrono::steady_clock::now();
  double team_saved = 0;  // what the team's chunks save with a core each
  if (parallel_.band_pass && rs.round >= 1) {
    const LoopClock prepared_clock(master_loops_);
    // The last round's bound vertices become the lagging ones: bound in this round too.
    std::vector<std::vector<VertexId>> lagging_of(master_loops_.ranges(r.bound.size()));
    master_loops_.run_indexed(r.bound.size(), [&](size_t range, size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v) {
        bound_before_[v] &= r.bound[v];
        if (bound_before_[v]) lagging_of[range].push_back(VertexId(v));
      }
    });
    std::vector<VertexId> lagging;
    for (const std::vector<VertexId>& some : lagging_of)
      lagging.insert(lagging.end(), some.begin(), some.end());
    BandPriority band(*master_queue_, std::move(bound_before_), r.ceiling);
    Simplifier pass(whole, band, standard_constraints(locked_, whole_components()));
    if (!copy_groups_.empty()) pass.join_copies(&copy_groups_);
    SimplifierLimits band_limits;
    band_limits.target_faces = std::max<uint64_t>(1, target_);
    band_limits.first_queue_around = &lagging;  // the band refuses every other edge
    // The next round as it would be without the band pass's collapses (it removes a few
    // hundred faces of a round's tens of thousands): its partition is drawn beside it.
    RoundStats before_band = rs;
    before_band.faces_after = whole.live_faces();
    const RoundPlan next =
        plan_round(before_band.faces_after, whole.live_vertices(),
                   scheduled_left_ - (r.scheduled && counts(before_band) ? 1 : 0), &before_band);
    LiveCopy copy;
    if (next.go) {
      const LoopClock copy_clock(master_loops_);
      copy = live_copy(whole, copy_groups_, master_loops_);
      foreseen_.copy_seconds = copy_clock.critical_seconds();
      foreseen_.subsets = next.subsets;
    }
    std::vector<CollapseRecord> band_records;
    PartitionOptions next_options;
    next_options.seed = round_seed(options_.seed, rs.round + 1);
    next_options.loops = &master_loops_;
    const double prepared = prepared_clock.critical_seconds();
    double partition_seconds = 0;
    const double team_before = team_saving();
    const Beside timed =
        run_beside(parallel_.threads, [&] { band_records = pass.run(band_limits, {}, cancel_); },
                   {[this] { append_pending(); },
                    [&] {
                      const LoopClock clock(master_loops_);
                      if (next.go)
                        foreseen_.vertex_subset = partition_copy(copy, next.subsets, next_options);
                      partition_seconds = clock.critical_seconds();
                    }});
    team_saved = team_saving() - team_before;
    foreseen_.beside_band = true;
    foreseen_.drawn = next.go;
    foreseen_.band_seconds = prepared + timed.work_seconds - team_saved - foreseen_.copy_seconds;
    foreseen_.append_seconds = timed.side_seconds[0];
    foreseen_.partition_seconds = partition_seconds;
    subsets_cpu_ += timed.side_cpu_elsewhere;
    rs.band_pass_collapses = band_records.size();
    if (carry_deferred_ && !band_records.empty())
      drop_changed(deferred_, whole.vertex_capacity(), {&band_records});
    append_list(std::move(band_records));
  }
  rs.band_pass_seconds = seconds_since(t) - team_saved;
  // With one thread, the band pass's time holds the append's and the partition's, which the
  // critical path counts, beyond the band pass, in the next round (or forgo_foreseen), and
  // the copy, counted with the partition.
  if (foreseen_.beside_band) rs.band_pass_seconds = foreseen_.band_seconds;
}

void ParallelBuilder::finish_round(Round& r) {
  RoundStats& rs = r.rs;
  bound_before_ = std::move(r.bound);
  rs.faces_after = whole_->live_faces();
  spdlog::debug(
      "parallel round {}: {} subsets {}->{} faces (goal {}{}; {} border faces), partition "
      "{:.3f} s, extract {:.3f} s, subsets {:.3f} s (slowest {:.3f} s CPU), merge {:.3f} s ({} "
      "replayed), band pass {} collapses in {:.3f} s",
      rs.round, r.subsets, rs.faces_before, rs.faces_after, rs.goal_faces,
      rs.border_limited ? ", bounded by the border band" : "", rs.border_faces,
      rs.partition_seconds, rs.extract_seconds, rs.subsets_seconds, rs.slowest_subset_cpu_seconds,
      rs.merge_seconds, r.replay.collapses, rs.band_pass_collapses, rs.band_pass_seconds);
  if (events_.merged) events_.merged(rs);
  if (r.scheduled && counts(rs)) --scheduled_left_;
  st_.round_stats.push_back(std::move(rs));
  if (progress_) {
    const uint64_t total = input_faces_ - target_;
    progress_(std::min<uint64_t>(input_faces_ - whole_->live_faces(), total), total);
  }
}

void ParallelBuilder::final_pass() {
  CollapseMesh& whole = *whole_;
  st_.rounds = uint32_t(st_.round_stats.size());
  const auto t = std::chrono::steady_clock::now();
  // The band pass's keys too, so that the final pass starts from the queue as it is.
  const std::vector<EdgeKey> carried =
      carry_keys_ ? keys_->current_keys(whole) : std::vector<EdgeKey>{};
  uint64_t reused_before = 0;
  std::unique_ptr<PriorityModule> continued = without_initialize(*master_queue_);
  // Components vanish here only: in the jobs and the band passes a lone triangle waits for
  // this pass, which costs it against the whole mesh's coarse collapses.
  Simplifier pass(
      whole, *continued,
      standard_constraints(locked_, whole_components(), !options_.keep_components, on_membrane_));
  if (!copy_groups_.empty()) pass.join_copies(&copy_groups_);
  SimplifierLimits limits;
  limits.target_faces = target_;
  if (options_.defer_recosting) limits.defer_above_faces = defer_line_;
  // The jobs' deferred edges that no key answers (sorted: a subsequence of a sorted list).
  std::erase_if(deferred_, [&](const DeferredEdge& d) { return has_key(carried, d.a, d.b); });
  limits.first_deferred = &deferred_;
  const uint64_t done_before = input_faces_ - whole.live_faces();
  const double setup_seconds = seconds_since(t);
  std::vector<CollapseRecord> final_records;
  auto progress = [&](uint64_t done, uint64_t) {
    const uint64_t total = input_faces_ - target_;
    if (progress_) progress_(std::min<uint64_t>(done_before + done, total), total);
  };
  // The pass runs on a compact copy of the live mesh (live_pass.h) where it can.
  std::optional<LivePass>& live = live_;
  auto run_pass = [&] {
    if (parallel_.final_pass_on_live_copy && runs_on_live_copy(*master_)) {
      LivePassInputs inputs;
      inputs.layout = &mesh_.layout;
      inputs.wedge_values = &mesh_.wedge_values;
      inputs.positions_are_float = mesh_.positions_are_float;
      inputs.locked = &locked_;
      inputs.groups = &copy_groups_;
      inputs.components = whole_components();
      inputs.components_may_vanish = !options_.keep_components;
      inputs.on_membrane = &on_membrane_;
      inputs.options = &options_;
      inputs.reference_diagonal = subset_options_.reference_diagonal;
      inputs.keys = carry_keys_ ? &carried : nullptr;
      inputs.deferred = &deferred_;
      inputs.team = team_ ? &*team_ : nullptr;
      live = run_on_live_copy(whole, *master_, inputs, limits, progress, cancel_, master_loops_);
    }
    if (live) {
      final_records = std::move(live->records);  // (the PM reads the live copy's end)
      return;
    }
    keys_->reset(carried);  // (the copy's memo takes them otherwise)
    reused_before = keys_->reused();
    final_records = pass.run(limits, progress, cancel_);
  };
  // The last round's records go into records_ beside it (append_pending).
  const double team_before = team_saving();
  const double loops_before = master_loops_.seconds() - master_loops_.critical_seconds();
  const Beside timed = run_beside(parallel_.threads, run_pass, {[this] { append_pending(); }});
  // (the live copy's listing counted at its loops' critical path)
  const double loops_saved =
      master_loops_.seconds() - master_loops_.critical_seconds() - loops_before;
  st_.final_work_seconds = timed.work_seconds - (team_saving() - team_before) - loops_saved;
  st_.final_pass_collapses = final_records.size();
  st_.final_pass_on_live_copy = live.has_value();
  st_.final_pass_seconds = setup_seconds + st_.final_work_seconds;
  st_.final_append_seconds = timed.side_seconds[0];
  subsets_cpu_ += timed.side_cpu_elsewhere;
  const SimplifierStats& fs = live ? live->stats : pass.stats();
  if (live) final_costings_ = live->costings;
  st_.stop_reason = fs.stop_reason;
  spdlog::debug(
      "final pass: {} keys carried in, {} answered from them; {} evaluations, {} vetoed, {} "
      "screened, {} requeued, {} stale, {} seam collapses ({} split)",
      carried.size(), live ? live->keys_reused : keys_->reused() - reused_before, fs.evaluations,
      fs.rejected, fs.screened, fs.requeued, fs.stale, fs.seam_collapses, fs.seams_split);
  if (events_.final_pass_done)
    events_.final_pass_done(st_.final_pass_collapses, st_.final_pass_seconds);
  append_list(std::move(final_records));
}

ProgressiveMesh ParallelBuilder::progressive_mesh() {
  release_free_memory();  // before the PM's arrays, the build's largest
  const LoopClock clock(master_loops_);
  PmBuildOptions build_options;
  build_options.keep_order = options_.keep_order;
  build_options.loops = &master_loops_;
  ProgressiveMesh pm = live_ ? build_pm_from_collapses(repaired_, live_->final_mesh(*whole_),
                                                       records_, build_options)
                             : build_pm_from_collapses(repaired_, *whole_, records_, build_options);
  pm.info.metric = master_->name();
  st_.pm_build_seconds = clock.critical_seconds();
  st_.collapses = records_.size();
  st_.critical_path_seconds = critical_path_seconds(st_);
  st_.seconds = seconds_since(start_);
  st_.cpu_seconds = subsets_cpu_ + (team_ ? team_->worker_cpu_seconds() : 0) +
                    (thread_cpu_seconds() - master_cpu_start_);
  // The master's: band passes and final pass.
  const uint64_t master_costings = master_->costings() - master_sample_costings_ + final_costings_;
  st_.costings = job_costings_ + sample_costings_ + master_costings;
  pm.info.seconds = st_.seconds;
  spdlog::debug(
      "parallel build p={} rounds={}: {} -> {} faces in {:.3f} s ({:.3f} s CPU; costings: {} "
      "by the jobs, {} by their samples, {} by the band passes and final pass), final pass {} "
      "collapses in {:.3f} s ({})",
      parallel_.subsets, st_.rounds, input_faces_, pm.base.face_count(), st_.seconds,
      st_.cpu_seconds, job_costings_, sample_costings_, master_costings, st_.final_pass_collapses,
      st_.final_pass_seconds, st_.stop_reason);
  return pm;
}

}  // namespace parapm
