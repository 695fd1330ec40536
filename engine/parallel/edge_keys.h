// Queue keys carried from round to round of the parallel construction, so that a round's jobs
// do not cost again every edge of their subsets before their first collapse: most of those
// edges have a key at the end of the previous round that the sequential build would still
// hold in its queue (decisions/notebook-2026-11.md, "Carried queue keys").
//
// The sequential build keeps an edge's key in its queue until a collapse changes one of its
// ends (vs or vt of the collapse; simplifier.h, the entries' stamps), even when collapses
// nearby have changed the edge's star: the key is costed again, with Costing::kPerform, when
// it reaches the top. A key the memo carries obeys the same rule, so a round's jobs start from
// the queue the sequential build would have, not from one costed afresh. Carrying keys changes
// the PM a little (a fresh costing sees the changed stars; measured in the same section).
//
// Why a job's key is current on the master after the round: a job costs only edges with two
// free ends (subset_rule.h), which no other subset can collapse; the master's state is the
// jobs' (job_state.h), so the key is the one the master would have computed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "simplify/modules.h"
#include "simplify/simplifier.h"

namespace parapm {

struct EdgeKey {
  VertexId a = kNoId;  // a < b
  VertexId b = kNoId;
  double cost = 0;  // the module's Costing::kQueue cost; NaN: it could not place the edge
};

// By (a, b).
void sort_keys(std::vector<EdgeKey>& keys);
// Whether `keys` (sorted by (a, b)) holds a key of edge (a, b).
bool has_key(const std::vector<EdgeKey>& keys, VertexId a, VertexId b);

// Throws Error(kInvalidInput) for a deferred edge that is not (a, b) with a < b below
// `vertex_capacity`: a job's deferred edges may come from a worker, and the master indexes its
// per-vertex arrays with them.
void check_deferred_edges(const std::vector<DeferredEdge>& edges, size_t vertex_capacity);

// A priority module that remembers the inner module's queue keys, and answers the first queue
// costing of an edge whose key was carried in (reset()) and whose ends no collapse has changed
// since, without costing it again. Keys costed here, or answered once, are remembered but not
// answered: within a run the simplifier asks again only when it needs a new costing (an end
// changed, or a rejected edge's star changed), so a run given the keys it would have costed
// itself is the run without them (tested). Any other costing than kQueue goes to the inner module.
// Not thread-safe (like the modules it wraps); its const reads (for_each_current*) may run
// concurrently.
class KeyMemo : public PriorityWrapper {
 public:
  KeyMemo(PriorityModule& inner, size_t vertex_capacity);
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override;
  // Answers what the keys answer, costs the rest together (the inner module's evaluate_each),
  // then remembers their keys in order.
  void evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                     Costing costing) override;
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) override;
  // (a carried key is answered once: what a key answers depends on when it is asked)
  bool queue_key_of_ends_only() const override { return false; }
  bool placed_when_queued_is_placed() const override { return false; }

  // Forgets every key, then carries `keys` in. Throws Error(kInvalidInput) for a key that is
  // not (a, b) with a < b below the vertex capacity (keys may come from a worker).
  void reset(const std::vector<EdgeKey>& keys);
  // Every current key (carried or costed here) of an edge between two live vertices, sorted.
  std::vector<EdgeKey> current_keys(const CollapseMesh& mesh) const;
  // Calls f(key) for the current keys listed at a (edges (a, b) with b > a), in no order.
  template <typename F>
  void for_each_current_at(VertexId a, F&& f) const {
    for (uint32_t i = head_[a]; i != kEnd; i = entries_[i].next)
      if (current(a, entries_[i])) f(EdgeKey{a, entries_[i].other, entries_[i].cost});
  }

  uint64_t reused() const { return reused_; }  // queue costings answered from a carried key

 private:
  static constexpr uint32_t kEnd = 0xffffffffu;
  struct Entry {
    VertexId other;  // the edge's larger end; the entry is listed at its smaller one
    uint32_t next;
    uint32_t time;  // collapses performed when it was costed or carried in
    bool carried;
    double cost;
  };
  bool current(VertexId a, const Entry& e) const {
    return changed_at_[a] <= e.time && changed_at_[e.other] <= e.time;
  }
  Entry* find(VertexId a, VertexId b) const;
  // A queue costing of edge (lo, hi) from its carried key `e` (find(lo, hi)'s answer), if it
  // is one still current (answered once: then forgotten as carried).
  bool answer(VertexId lo, Entry* e, CollapseCandidate& out, bool& placed);
  // Overwrites `found` (find(a, b)'s answer) or lists a new entry at a.
  void store(Entry* found, VertexId a, VertexId b, double cost, bool carried) const;

  mutable std::vector<uint32_t> head_;  // per vertex: its first entry, kEnd for none
  mutable std::vector<Entry> entries_;
  std::vector<uint32_t> changed_at_;  // per vertex: the last collapse it was vs or vt of
  uint32_t time_ = 0;
  mutable uint64_t reused_ = 0;
};

}  // namespace parapm
