#include "parallel/edge_keys.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "util/error.h"

namespace parapm {

void sort_keys(std::vector<EdgeKey>& keys) { std::sort(keys.begin(), keys.end(), ByEdge{}); }

bool has_key(const std::vector<EdgeKey>& keys, VertexId a, VertexId b) {
  return std::binary_search(keys.begin(), keys.end(), EdgeKey{a, b, 0}, ByEdge{});
}

void check_deferred_edges(const std::vector<DeferredEdge>& edges, size_t vertex_capacity) {
  for (const DeferredEdge& d : edges)
    if (d.a >= d.b || d.b >= vertex_capacity)
      throw_invalid("deferred edge (" + std::to_string(d.a) + ", " + std::to_string(d.b) +
                    ") is not an edge of a mesh of " + std::to_string(vertex_capacity) +
                    " vertices");
}

KeyMemo::KeyMemo(PriorityModule& inner, size_t vertex_capacity)
    : PriorityWrapper(inner), head_(vertex_capacity, kEnd), changed_at_(vertex_capacity, 0) {}

KeyMemo::Entry* KeyMemo::find(VertexId a, VertexId b) const {
  for (uint32_t i = head_[a]; i != kEnd; i = entries_[i].next)
    if (entries_[i].other == b) return &entries_[i];
  return nullptr;
}

void KeyMemo::store(Entry* found, VertexId a, VertexId b, double cost, bool carried) const {
  if (found) {
    *found = {b, found->next, time_, carried, cost};
    return;
  }
  entries_.push_back({b, head_[a], time_, carried, cost});
  head_[a] = uint32_t(entries_.size() - 1);
}

bool KeyMemo::evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                       Costing costing) {
  if (costing != Costing::kQueue) return inner_.evaluate(mesh, a, b, out, costing);
  const VertexId lo = std::min(a, b), hi = std::max(a, b);
  Entry* const e = find(lo, hi);
  bool placed = false;
  if (answer(lo, e, out, placed)) return placed;
  placed = inner_.evaluate(mesh, a, b, out, costing);
  // (The inner module never touches the memo, so `e` still points at the entry.)
  store(e, lo, hi, placed ? out.cost : std::numeric_limits<double>::quiet_NaN(), false);
  return placed;
}

void KeyMemo::evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                            Costing costing) {
  if (costing != Costing::kQueue) {
    inner_.evaluate_each(mesh, edges, costing);
    return;
  }
  const std::span<const size_t> costed = evaluate_picked(mesh, edges, costing, [&](EdgeCosting& e) {
    const VertexId lo = std::min(e.a, e.b);
    return !answer(lo, find(lo, std::max(e.a, e.b)), e.candidate, e.placed);
  });
  // (The edges are distinct: answering or storing one changes no other's entry.)
  for (const size_t i : costed) {
    const EdgeCosting& e = edges[i];
    const VertexId lo = std::min(e.a, e.b), hi = std::max(e.a, e.b);
    store(find(lo, hi), lo, hi,
          e.placed ? e.candidate.cost : std::numeric_limits<double>::quiet_NaN(), false);
  }
}

bool KeyMemo::answer(VertexId lo, Entry* e, CollapseCandidate& out, bool& placed) {
  if (!e || !e->carried || !current(lo, *e)) return false;
  ++reused_;
  e->carried = false;  // answered once: the simplifier's next costing of it needs a fresh one
  // A queue costing's caller reads only the cost (modules.h: the edge is costed again, with
  // kPerform, before it is collapsed).
  out.cost = e->cost;
  placed = !std::isnan(e->cost);
  return true;
}

void KeyMemo::collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) {
  inner_.collapsed(mesh, done, edge);
  ++time_;
  changed_at_[done.vs] = changed_at_[done.vt] = time_;
}

void KeyMemo::reset(const std::vector<EdgeKey>& keys) {
  head_.assign(head_.size(), kEnd);
  entries_.clear();
  entries_.reserve(keys.size());
  for (const EdgeKey& k : keys) {
    // Keys may come from a worker: refused before they index anything.
    if (k.a >= k.b || k.b >= head_.size())
      throw_invalid("queue key (" + std::to_string(k.a) + ", " + std::to_string(k.b) +
                    ") is not an edge of a mesh of " + std::to_string(head_.size()) + " vertices");
    store(find(k.a, k.b), k.a, k.b, k.cost, true);
  }
}

std::vector<EdgeKey> KeyMemo::current_keys(const CollapseMesh& mesh) const {
  std::vector<EdgeKey> keys;
  for (VertexId a = 0; a < head_.size(); ++a) {
    if (!mesh.vertex_alive(a)) continue;
    for_each_current_at(a, [&](const EdgeKey& k) {
      if (mesh.vertex_alive(k.b)) keys.push_back(k);
    });
  }
  sort_keys(keys);
  return keys;
}

}  // namespace parapm
