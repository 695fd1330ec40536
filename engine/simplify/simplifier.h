// The collapse driver (Hoppe 96 section 4; Garland & Heckbert 97 section 4): every edge in a
// priority queue by cost; pop the cheapest, re-check its legality, collapse it, re-cost the
// edges around the surviving vertex. Produces the ordered collapse records from which the
// Progressive Mesh is built, and which a worker streams back to the coordinator.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "simplify/collapse_mesh.h"
#include "simplify/copy_groups.h"
#include "simplify/key_rank.h"
#include "simplify/modules.h"
#include "simplify/tiered_queue.h"
#include "util/chunked_loops.h"
#include "util/progress.h"
#include "util/zeroed_array.h"

namespace parapm {

// One performed collapse, in the ids of the simplifier's mesh. Its inverse is the vertex split
// of the PM: fl = (vs, vt, vl) and fr = (vt, vs, vr) come back.
struct CollapseRecord {
  VertexId vs = kNoId;
  VertexId vt = kNoId;
  VertexId vl = kNoId;  // apex of fl, or kNoId on a boundary edge
  VertexId vr = kNoId;  // apex of fr, or kNoId
  FaceId fl = kNoId;
  FaceId fr = kNoId;
  Vec3 vs_position{};  // before the collapse
  Vec3 vt_position{};
  Vec3 position{};  // of vs after the collapse
  std::array<WedgeId, 6> corner_wedges{kNoId, kNoId, kNoId, kNoId, kNoId, kNoId};
  double cost = 0;
  float error = 0;  // the priority module's geometric error, model units
  // Wedges whose values the collapse changed (E_scalar), with their values after it
  // (floats_per_wedge each); the values before are those the previous records left.
  std::vector<WedgeId> changed_wedges;
  std::vector<float> changed_values;
  // Set on a record decoded from a worker (job_codec.h), which leaves out what the
  // coordinator's mesh tells: vl, vr, corner_wedges, vs_position and vt_position are the
  // replay's to find (collapse_merge.h), which then clears it.
  bool to_complete = false;
};

// An edge waiting in the queue for a costing (SimplifierLimits::first_deferred), a < b.
struct DeferredEdge {
  VertexId a = kNoId;
  VertexId b = kNoId;
  float key = 0;  // its last costing's key; infinite: the module refused it then
};

// Edge records (DeferredEdge, the parallel build's EdgeKey: anything with ends a < b) in
// (a, b) order, the order their lists are kept and searched in.
struct ByEdge {
  template <typename X, typename Y>
  bool operator()(const X& x, const Y& y) const {
    return x.a != y.a ? x.a < y.a : x.b < y.b;
  }
};

// Sorts `edges` by (a, b) and keeps one record per edge: the first of its records (stable).
template <typename Edge>
void sort_unique_edges(std::vector<Edge>& edges) {
  std::stable_sort(edges.begin(), edges.end(), ByEdge{});
  edges.erase(std::unique(edges.begin(), edges.end(),
                          [](const Edge& x, const Edge& y) { return x.a == y.a && x.b == y.b; }),
              edges.end());
}

// The records of sorted `lists`, merged into `out` by edge, one per edge: among equal edges the
// earlier list's record, as the stable sort keeps it (a heap of the lists' next records).
template <typename Edge>
void merge_sorted_edges(const std::vector<std::span<const Edge>>& lists, std::vector<Edge>& out) {
  std::vector<std::pair<size_t, size_t>> heads;  // (list, index)
  auto later = [&](const std::pair<size_t, size_t>& x, const std::pair<size_t, size_t>& y) {
    const Edge& ex = lists[x.first][x.second];
    const Edge& ey = lists[y.first][y.second];
    if (ex.a != ey.a) return ex.a > ey.a;
    if (ex.b != ey.b) return ex.b > ey.b;
    return x.first > y.first;
  };
  for (size_t l = 0; l < lists.size(); ++l)
    if (!lists[l].empty()) heads.emplace_back(l, 0);
  std::make_heap(heads.begin(), heads.end(), later);
  while (!heads.empty()) {
    std::pop_heap(heads.begin(), heads.end(), later);
    auto& [l, i] = heads.back();
    const Edge& e = lists[l][i];
    if (out.empty() || out.back().a != e.a || out.back().b != e.b) out.push_back(e);
    if (++i < lists[l].size())
      std::push_heap(heads.begin(), heads.end(), later);
    else
      heads.pop_back();
  }
}

// sort_unique_edges of the lists joined in order, merged where each list is sorted already (the
// lists of a parallel build's jobs and the master's): each of `loops`' ranges of first ends
// merges its part of every list, O(n log lists) in all.
template <typename Edge>
std::vector<Edge> merge_unique_edges(const std::vector<const std::vector<Edge>*>& lists,
                                     ChunkedLoops& loops) {
  std::vector<Edge> out;
  size_t total = 0, ends = 0;  // ends: past the largest first end
  bool sorted = true;
  for (const std::vector<Edge>* list : lists) {
    total += list->size();
    sorted = sorted && std::is_sorted(list->begin(), list->end(), ByEdge{});
    if (!list->empty()) ends = std::max(ends, size_t(list->back().a) + 1);
  }
  out.reserve(total);
  if (!sorted) {
    for (const std::vector<Edge>* list : lists) out.insert(out.end(), list->begin(), list->end());
    sort_unique_edges(out);
    return out;
  }
  std::vector<std::vector<Edge>> parts(loops.ranges(ends));
  loops.run_indexed(ends, [&](size_t range, size_t begin, size_t end) {
    std::vector<std::span<const Edge>> here;
    for (const std::vector<Edge>* list : lists) {
      const auto from = std::partition_point(list->begin(), list->end(),
                                             [&](const Edge& e) { return e.a < begin; });
      const auto to =
          std::partition_point(from, list->end(), [&](const Edge& e) { return e.a < end; });
      here.emplace_back(std::to_address(from), size_t(to - from));
    }
    merge_sorted_edges(here, parts[range]);
  });
  for (const std::vector<Edge>& part : parts) out.insert(out.end(), part.begin(), part.end());
  return out;
}

template <typename Edge>
std::vector<Edge> merge_unique_edges(const std::vector<const std::vector<Edge>*>& lists) {
  ChunkedLoops one_thread;
  return merge_unique_edges(lists, one_thread);
}

struct SimplifierLimits {
  size_t target_faces = 0;  // stop once the live face count is <= this (0: go as far as legal)
  // Deferred re-costing, with a costly priority module: while more faces than this are live,
  // the edges around vs after a collapse are not costed at once. Each goes back into the queue
  // a little below its last key (the lower of its two faces' remembered keys, less half its
  // magnitude; at the end of the queue if the module refused it last time) and is costed when
  // it comes to the top, then queued again at its true key: most of them change again before
  // they get there, so about a third of the costings are saved (decisions/notebook-2026-11.md,
  // "Deferred re-costing"). Below it every one is costed at once, so the coarse levels, where
  // one collapse out of order costs most, keep the exact order. SIZE_MAX: never deferred.
  size_t defer_above_faces = SIZE_MAX;
  // When set, the first queue holds only the edges with an end in this list (live vertices),
  // not every edge of the mesh: for a module that refuses every other edge until a collapse
  // changes it (the parallel build's band pass, whose lagging vertices are a thin band of a
  // large mesh), the same run, without costing the whole mesh's edges only to refuse them.
  const std::vector<VertexId>* first_queue_around = nullptr;
  // Edges whose last costing is known to be outdated (a collapse changed an end since), each
  // with that costing's key, sorted by (a, b): while the run defers (above
  // defer_above_faces), its first queue takes them deferred, below that key, as a run that had
  // made those collapses itself would hold them, instead of costing them at once. Another
  // key (infinite: refused), or an edge that is not live, is taken as it is or ignored. The
  // parallel build carries a job's still-deferred edges (deferred_edges()) into the next
  // round's jobs, which would otherwise cost them all afresh.
  const std::vector<DeferredEdge>* first_deferred = nullptr;
  // An edge costing more is not collapsed: it stays in the queue at its cost, as a run without
  // the ceiling would hold it, and the run ends once the queue's cheapest key is above the
  // ceiling rounded to a float, as keys are ("cost ceiling reached"). A parallel build's job stops
  // at its round's water level so; its queue at the end, real keys throughout, is what the next
  // round starts from (deferred_edges()). A deferred edge comes out below its last key, so one
  // whose cost has fallen under the ceiling since is still taken unless its last key was twice the
  // ceiling.
  double max_cost = std::numeric_limits<double>::infinity();
};

// The sequential build defers re-costing down to this fraction of the input's faces (the
// parallel build's default handover, so that its final pass costs at once, as this does).
constexpr double kDeferRecostingAboveRatio = 0.1;

// That fraction of `input_faces`, rounded: the one line both builds compare face counts with.
inline size_t defer_recosting_line(uint64_t input_faces) {
  return size_t(std::llround(kDeferRecostingAboveRatio * double(input_faces)));
}

struct SimplifierStats {
  uint64_t collapses = 0;
  uint64_t rejected = 0;     // pops vetoed by a constraint
  uint64_t stale = 0;        // pops of outdated queue entries
  uint64_t reevaluated = 0;  // rejected edges costed again after their star changed
  uint64_t evaluations = 0;  // calls to the priority module's evaluate
  // Popped edges whose cost, costed afresh, was above the next key: queued again with it.
  uint64_t requeued = 0;
  // Of those, and of the edges checked as they were queued (queue_checked), taken out again
  // with their star unchanged: their costing kept.
  uint64_t requeue_reused = 0;
  // With a costly priority module: edges the topological rules vetoed before any costing
  // (retried after their star changed, or on top of the queue: those count as rejected too).
  uint64_t screened = 0;
  uint64_t deferred = 0;  // edges queued below their last key instead of costed at once
  // Of the rejected: edges vetoed as they were queued (Simplifier::queue_checked), never popped.
  uint64_t vetoed_when_queued = 0;
  uint64_t compactions = 0;     // passes dropping the queue's stale entries at once
  uint64_t over_ceiling = 0;    // popped edges whose cost was above SimplifierLimits::max_cost
  uint64_t seam_collapses = 0;  // performed (join_copies), each one record per copy removed
  uint64_t seams_in_turn = 0;   // of those, tried in turn first (their rings overlap)
  // Seam collapses stopped midway: an earlier copy's collapse made a later one's illegal (the
  // group's remaining copies leave in a later seam collapse).
  uint64_t seams_split = 0;
  std::string stop_reason;  // why the loop ended
};

class Simplifier {
 public:
  Simplifier(CollapseMesh& mesh, PriorityModule& priority,
             std::vector<std::unique_ptr<ConstraintModule>> constraints);
  // (its queue asks it which entries are stale: it stays where it was made)
  Simplifier(const Simplifier&) = delete;
  Simplifier& operator=(const Simplifier&) = delete;

  // Runs until the target is reached or no legal collapse is left. Calls progress every few
  // hundred collapses and polls `cancel` (may be null); on cancellation throws and leaves the
  // mesh in a consistent state.
  std::vector<CollapseRecord> run(const SimplifierLimits& limits, const ProgressCallback& progress,
                                  const CancelToken* cancel);
  const SimplifierStats& stats() const { return stats_; }
  // Seam collapses (copy_groups.h): an edge between copies of two groups (which the modules
  // treat as locked, so never collapse) is costed and collapsed as a whole: every live copy of
  // one group collapses into a copy of the other adjacent to it. The survivors stay where they
  // are, or, when every copy of their group is one, all go to one place: the one of least
  // summed cost (PriorityModule::evaluate_seam) among where they are and where each
  // collapse alone would put its survivor. The cheaper way round is taken. A copy in a part
  // too small to shrink (ConstraintModule::drop_too_small) stays where it is, beside the seam.
  // Legal when each collapse is legal on the mesh before the first and, unless their rings
  // (both ends and their neighbours) are apart, so that none changes what another's rules
  // read, when they pass the neighbourhood rules made in turn on a copy of the faces around
  // their ends (each is checked again before it is made). Its records follow one another; a run
  // does not stop between them, not even at its target. A group of more than kMaxSeamCopies live
  // copies stays. Off (null) by default; `groups` must outlive the run.
  void join_copies(const CopyGroups* groups) { groups_ = groups; }
  static constexpr size_t kMaxSeamCopies = 16;
  // Edge {a, b} of the mesh as it is, costed as a run would cost it with `costing` (kQueue: its
  // queue key; kEstimate): the module's costing or, between copies of two groups, the seam
  // collapse's. Outside a run, the rules are not asked (not even which copies stay in parts
  // too small to shrink): an estimate of the mesh's costs (round_shares.h), for which the
  // constraints may be none and the module already set up.
  bool cost_now(VertexId a, VertexId b, Costing costing, CollapseCandidate& out) {
    return cost_edge(a, b, out, costing);
  }
  // After run(): the edges still waiting in the queue to be costed (deferred, neither end
  // changed since), with the key they were deferred from, sorted by (a, b). Empty when the run
  // did not defer.
  std::vector<DeferredEdge> deferred_edges();

 private:
  // 16 bytes, so that more of the heap stays in cache. The stamp is the sum of the two
  // vertices' versions when the entry was pushed: versions only grow, so the sum is unchanged
  // exactly when neither end has changed since. Its top bit marks a deferred entry, whose
  // edge is to be costed when it comes out, the next a requeued one, whose costing requeued_
  // may hold (versions count collapses, far below 2^30).
  static constexpr uint32_t kDeferred = 0x80000000u;
  static constexpr uint32_t kRequeued = 0x40000000u;
  static constexpr uint32_t kVersions = ~(kDeferred | kRequeued);
  struct Entry {
    VertexId a;
    uint32_t key;  // the queue key's rank (key_rank.h): the order of the float key
    VertexId b;
    uint32_t stamp;
    static Entry of(float key, VertexId a, VertexId b, uint32_t stamp) {
      return {a, key_rank(key), b, stamp};
    }
    float cost() const { return rank_key(key); }  // the float key
    // The key's rank and a, the order's first two words, as one number.
    uint64_t rank_and_a() const { return uint64_t(key) << 32 | a; }
  };
  struct Before {  // by key, ties broken by the edge's ids for determinism
    bool operator()(const Entry& x, const Entry& y) const {
      const uint64_t kx = x.rank_and_a(), ky = y.rank_and_a();
      return kx != ky ? kx < ky : x.b < y.b;
    }
  };

  void push_edge(VertexId a, VertexId b);
  // run()'s first steps: the per-run state reset (and the modules initialised), then the
  // first queue (every live edge once, or those around limits.first_queue_around).
  void begin_run(const SimplifierLimits& limits);
  void build_first_queue(const SimplifierLimits& limits, const CancelToken* cancel);
  // The first queue from the edges around `vertices` only (SimplifierLimits::first_queue_around).
  void queue_edges_around(const std::vector<VertexId>& vertices, const CancelToken* cancel);
  // Queues edge {a, b} below its remembered key, uncosted; false when it has none.
  bool defer_edge(VertexId a, VertexId b);
  // The entry defer_edge would push; false when the edge has no remembered key.
  bool deferred_entry(VertexId a, VertexId b, Entry& entry);
  // The lower of edge {a, b}'s faces' remembered keys; NaN for none.
  float remembered_key(VertexId a, VertexId b);
  // The key last computed for edge {a, b} stays with its faces (the two corners' slots of
  // face_keys_), through collapses that rename an end: the faces keep their ids and corners.
  void remember_key(VertexId a, VertexId b, float key);
  // The two faces' slots of edge {a, b} in face_keys_ (null for a missing face).
  std::array<float*, 2> key_slots(VertexId a, VertexId b);
  // Costs edge {a, b}; false when the module cannot place it.
  bool queue_entry(VertexId a, VertexId b, Entry& entry);
  // A seam's queue costing: cost_seam's answer and cost.
  struct SeamKey {
    bool placed = false;
    double cost = 0;
  };
  // By the groups of an edge's ends (a < b), the first's in the high half.
  using SeamCostings = std::unordered_map<uint64_t, SeamKey>;
  // While build_first_queue runs: the seams costed so far, each costed once (queue_entry).
  SeamCostings* first_queue_seams_ = nullptr;
  // The entry of edge {a, b} (a < b) from its queue costing, its key remembered; false (and
  // the refusal remembered) when the costing could not place it.
  bool entry_of_costing(VertexId a, VertexId b, bool placed, double cost, Entry& entry);
  // requeue_around's pushes with a costly module: the costings of a collapse's edges in one
  // PriorityModule::evaluate_each.
  void requeue_costly(VertexId vs, bool defer);
  // The queue key of edge {a, b} costing `cost`: the cost as a float, but a cost of exactly
  // zero (a flat neighbourhood, where every edge ties) goes below every positive key, shorter
  // edges first (-1 / length^2). Ties left to the ids let the smallest id absorb its flat
  // neighbours one after the other: a hub whose slivers veto the collapses around it.
  // (Lindstrom-Turk's shape term settles the same ties by edge length.)
  float key_of(double cost, VertexId a, VertexId b) const;
  // Queues edge {a, b} as push_edge does after a collapse. With check_when_queued_, an edge
  // keyed at or below that collapse's key (it comes out before anything queued earlier above
  // it, often next) is costed for its collapse now: when a rule of its star vetoes it, it
  // waits among the vetoed edges instead of in the queue, as its pop would have left it (the
  // same star, so the same costing and veto: its next retry comes with the next change of its
  // star either way, and its key is the same then); when none does, its entry keeps the
  // costing for its pop (requeued_).
  // `folded`: the face whose fold vetoed the edge last (ConstraintModule::folded_face), or
  // kNoId.
  void queue_checked(VertexId a, VertexId b, const SimplifierLimits& limits, FaceId folded = kNoId);
  // queue_checked's costing of `entry`'s edge for its collapse (the queue costing's, when it is
  // that: CollapseCandidate::as_performed): true when a rule of its star vetoes it (then
  // rejected), false when it is to be queued (its costing kept when it passes). `folded` is
  // tested first: a face still folding vetoes it as the geometry rule would. Without one, the
  // rules that read the edge alone come before a costing that must be made, where it is sure
  // to be placed and no ceiling applies: a veto either way.
  bool vetoed_when_queued(Entry& entry, const SimplifierLimits& limits, FaceId folded);
  void remember_rejected(VertexId v, VertexId other, FaceId folded);
  // Edge {a, b} among the vetoed edges of both ends, with the face whose fold vetoed it.
  void reject(VertexId a, VertexId b, FaceId folded = kNoId);
  bool topologically_legal(VertexId a, VertexId b) const;
  // The same with the edge's faces given; with star_local_only, the rules that are also
  // star_local() (those vetoed_when_queued asks).
  bool topologically_legal(VertexId a, VertexId b, const EdgeFaces& edge,
                           bool star_local_only) const;
  bool is_stale(const Entry& entry) const {
    return !mesh_.vertex_alive(entry.a) || !mesh_.vertex_alive(entry.b) ||
           version_[entry.a] + version_[entry.b] != (entry.stamp & kVersions);
  }
  // Starts loading what is_stale(entry) reads: the entry next in line, while this one is
  // handled (most entries that come out are stale, each check a cache miss otherwise).
  void prefetch_staleness(const Entry& entry) const {
    mesh_.prefetch_vertex_alive(entry.a);
    mesh_.prefetch_vertex_alive(entry.b);
    __builtin_prefetch(&version_[entry.a]);
    __builtin_prefetch(&version_[entry.b]);
    mesh_.prefetch_vertex(entry.a);
    mesh_.prefetch_vertex(entry.b);
    priority_.will_cost(entry.a, std::span(&entry.b, 1));
  }
  void compact_queue();
  // All constraints; with topology_checked, those that are not topological(); with
  // star_checked (a kept requeued candidate, which passed them all, its star unchanged since),
  // those that are not star_local().
  // `folded`, when given: on a veto, the vetoing rule's folded_face().
  bool legal(const CollapseCandidate& candidate, const EdgeFaces& edge,
             bool topology_checked = false, bool star_checked = false,
             FaceId* folded = nullptr) const;
  CollapseRecord perform(CollapseCandidate candidate, const EdgeFaces& edge);
  // After a collapse with survivor vs: its version bumped, the vetoed edges around the changed
  // star retried, the edges around vs queued again.
  void requeue_around(VertexId vs, VertexId vt, const SimplifierLimits& limits);
  // The module's costing of edge {a, b}, or the seam collapse's between their groups.
  bool cost_edge(VertexId a, VertexId b, CollapseCandidate& out, Costing costing);
  // Whether edge {a, b} joins two copies: a seam's, costed by cost_seam.
  bool seam_edge(VertexId a, VertexId b) const {
    return groups_ && groups_->is_copy(a) && groups_->is_copy(b);
  }
  // Every live copy of group `from` (as vt) with the copy of group `into` adjacent to it of
  // the smallest id (as vs), into seam_pairs_, but for copies in parts too small to shrink
  // (ConstraintModule::drop_too_small: they stay); false when a copy has no such neighbour,
  // or when there are too many copies or none to collapse.
  bool pair_seam(uint32_t from, uint32_t into);
  // Whether every live copy of group `into` is a survivor in seam_pairs_.
  bool all_survive(uint32_t into) const;
  // Whether seam_pairs_' rings (both ends and their neighbours) are apart: then no collapse
  // changes what another's rules read.
  bool rings_apart();
  // Whether seam_pairs_' collapses, made one after the other with the survivors at `place`,
  // each pass the neighbourhood rules: tried on a copy of the faces around their ends.
  bool seam_holds_in_turn(const Vec3& place);
  bool cost_seam(VertexId a, VertexId b, CollapseCandidate& out, Costing costing);
  // Performs the seam collapse `seam` names (its first pair and place); false, and nothing
  // done, when one of its collapses is illegal on the mesh as it is.
  bool perform_seam(const CollapseCandidate& seam, const SimplifierLimits& limits,
                    std::vector<CollapseRecord>& records);

  CollapseMesh& mesh_;
  PriorityModule& priority_;
  std::vector<std::unique_ptr<ConstraintModule>> constraints_;
  TieredQueue<Entry, Before> queue_;
  size_t compacted_size_ = 0;  // the queue's size after the last compact_queue()
  // priority_.costly(): retried and top edges meet the topological rules before any costing.
  bool screen_ = false;
  // A cheap module whose queue keys read the edge's ends only (queue_checked).
  bool check_when_queued_ = false;
  float last_key_ = 0;  // the key of the collapse last made
  // Per vertex, from zeroed pages (a run over a band of a large mesh touches the band's).
  ZeroedArray<uint32_t> version_;
  // A vetoed edge's other end, and the face whose fold vetoed it last (kNoId: none).
  struct Vetoed {
    VertexId other;
    FaceId folded;
  };
  // Per vertex: the edges vetoed since its last change, a list of rejected_lists_ (its index
  // + 1 in rejected_slot_; 0: none yet).
  ZeroedArray<uint32_t> rejected_slot_;
  std::vector<std::vector<Vetoed>> rejected_lists_;
  std::vector<Vetoed>* rejected_list(VertexId v) {
    return rejected_slot_[v] ? &rejected_lists_[rejected_slot_[v] - 1] : nullptr;
  }
  // Requeued edges' costings, kept while neither end's star version changes (no collapse
  // changed the edge's star): the edge needs no new costing when it comes out again.
  static uint64_t edge_key(VertexId a, VertexId b) { return uint64_t(a) << 32 | b; }
  bool take_requeued(const Entry& entry, CollapseCandidate& out);
  struct KeptCosting {
    uint32_t star_version_a, star_version_b;  // the ends' (a < b) when it was costed
    CollapseCandidate candidate;
  };
  // Whether a requeued costing is of no more use: the edge's star changed after it.
  bool requeued_outdated(uint64_t key, const KeptCosting& kept) const {
    return mesh_.star_version(VertexId(key >> 32)) != kept.star_version_a ||
           mesh_.star_version(VertexId(key & 0xffffffffu)) != kept.star_version_b;
  }
  void forget_outdated_requeued();
  std::unordered_map<uint64_t, KeptCosting> requeued_;
  bool defer_ = false;  // costly() and a limit below SIZE_MAX
  // 3 per face: the key of the edge from corner k; NaN: none yet, infinite: refused
  std::vector<float> face_keys_;
  const CopyGroups* groups_ = nullptr;
  std::vector<SeamPair> seam_pairs_;
  std::vector<Vec3> seam_places_;
  // While a seam collapse requeues around its survivors: the group pairs queued so far.
  bool seam_already_queued(VertexId a, VertexId b);
  bool queueing_seams_ = false;
  std::vector<std::pair<uint32_t, uint32_t>> queued_seams_;
  std::vector<SeamCosting> seam_costs_;  // cost_seam's, one per place of a way round
  std::vector<uint32_t> seam_mark_;      // per vertex: the pair whose ring holds it (rings_apart)
  std::vector<FaceId> seam_faces_;
  std::vector<std::unique_ptr<ConstraintModule>> seam_rules_;  // neighbourhood_constraints()
  uint32_t seam_stamp_ = 0;
  std::vector<VertexId> ring_, seam_ring_;
  // queue_entry's costing, reused: a queue key reads only its cost, and a fresh candidate's
  // zeroing cost as much as a cheap costing.
  CollapseCandidate queued_;
  CollapseCandidate checked_;  // vetoed_when_queued's
  struct Retry {
    VertexId a, b;
    FaceId folded;
  };
  std::vector<Retry> retry_;
  // Edge {a, b} (a < b) planned as costed_[costings] for evaluate_each; returns that index and
  // counts it (costings, and the evaluation in stats_).
  size_t plan_costing(VertexId a, VertexId b, size_t& costings);
  // requeue_costly's pushes in order: an entry, or the index of its costing in costed_.
  static constexpr size_t kNotCosted = ~size_t{0};
  struct PlannedPush {
    Entry entry;
    size_t costing = kNotCosted;
  };
  std::vector<PlannedPush> planned_;
  std::vector<EdgeCosting> costed_;
  SimplifierStats stats_;
};

}  // namespace parapm
