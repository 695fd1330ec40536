// Greedy graph partitioning, algorithm G of
//   P. Ciarlet, Jr. and F. Lamour, "An Efficient Low Cost Greedy Graph Partitioning
//   Heuristic", UCLA CAM report 94-1 (1994),
// as revised for mesh simplification in Langis (1999): subsets are weighted, and a subset
// that gets locked in continues from a new seed instead of restarting the partition.
//
// One subset is grown at a time by breadth-first fronts; a vertex is "marked" once it belongs
// to a subset, and its "updated degree" is its number of unmarked neighbours. Starting where
// the updated degree is small keeps the unmarked region compact (few vertices are cut off),
// which is what keeps the cut small. Each vertex is marked once and each edge is looked at a
// constant number of times from each end: O(|E|), independent of p.
#include <algorithm>
#include <optional>
#include <vector>

#include "partition/partition_internal.h"
#include "util/fresh_pages.h"

namespace parapm::partition_detail {
namespace {

// Balance by faces (graph.has_faces()). A face goes to the majority subset of its corners,
// else the smallest of the three (assign_faces). Counted by their corners, the subsets grown
// first end a little above their share of the faces (their fronts, taken by least updated
// degree, complete faces) and the last one short by all of their excess. So the greedy counts
// a face once its owner is
// settled (its second corner in the subset of its first, or its third corner), 3 per face as
// the targets count corners, and grows subset k until the faces settled so far reach the
// targets of subsets 0 ... k together: no subset's excess carries over to the last. (A face
// settled by three subsets belongs to the smallest, an earlier one than the subset that
// counts it; the next subsets make up for it.)
class SettledFaces {
 public:
  SettledFaces(const VertexGraph& graph, ChunkedLoops& loops)
      : graph_(graph), faces_(filled_touched(graph.face_count, Face{}, loops)) {}

  // Corner units settled when v joins subset k.
  uint64_t join(uint32_t v, uint32_t k) {
    uint64_t settled = 0;
    for (uint32_t f : graph_.faces_of(v)) settled += step(faces_[f], k) ? 3 : 0;
    return settled;
  }

  // What join() of every vertex of `front` would return in total, without joining them.
  uint64_t gain(const std::vector<uint32_t>& front, uint32_t k) {
    for (uint32_t v : front)
      for (uint32_t f : graph_.faces_of(v)) ++faces_[f].pending;
    uint64_t settled = 0;
    for (uint32_t v : front)
      for (uint32_t f : graph_.faces_of(v)) {
        Face& face = faces_[f];
        if (face.pending == 0) continue;  // done from another of its corners
        Face trial = face;
        bool any = false;
        for (uint32_t i = 0; i < face.pending; ++i) any = step(trial, k) || any;
        settled += any ? 3 : 0;
        face.pending = 0;
      }
    return settled;
  }

 private:
  // Per face, together: one cache line for all three.
  struct Face {
    uint32_t first = kNoId;  // the subset of its first corner in a subset
    uint8_t corners = 0;     // its corners in subsets so far, 4 once settled
    uint8_t pending = 0;     // its corners in the front gain() looks at
  };

  // One more corner of a face in k; true when that settles its owner.
  static bool step(Face& face, uint32_t k) {
    switch (face.corners) {
      case 0:
        face.first = k;
        face.corners = 1;
        return false;
      case 1:
        if (face.first == k) break;  // a pair in k
        face.corners = 2;            // two subsets: the third corner decides
        return false;
      case 2:
        break;
      default:
        return false;  // settled already
    }
    face.corners = 4;
    return true;
  }

  const VertexGraph& graph_;
  std::vector<Face> faces_;
};

// Unmarked vertices next to the marked region, by updated degree, for continuation seeds: a
// list per degree, in the order the vertices reached it. A vertex's updated degree only falls,
// so it enters each list at most once, and an entry is current while its vertex is unmarked and
// still of that degree; min() skips the others, for good. The order of a BucketQueue whose key
// is changed at every fall, without unlinking anything at each one.
class FallingDegrees {
 public:
  // The lists lie in one block, each with room for every vertex whose degree exceeds its own
  // (the vertices that can fall to it): 4 bytes per neighbour entry of the graph, no growth.
  FallingDegrees(const VertexGraph& graph, uint32_t max_degree, ChunkedLoops& loops)
      : heads_(size_t(max_degree) + 1, 0), min_key_(max_degree + 1) {
    std::vector<size_t> of_degree(size_t(max_degree) + 1, 0);
    for (uint32_t v = 0; v < graph.vertex_count(); ++v) ++of_degree[graph.degree(v)];
    size_t above = graph.vertex_count(), room = 0;  // vertices whose degree exceeds d
    for (uint32_t d = 0; d <= max_degree; ++d) {
      heads_[d] = room;
      above -= of_degree[d];
      room += above;
    }
    resize_touched(entries_, room, loops);
    ends_ = heads_;
  }

  void push(uint32_t v, uint32_t degree) {
    entries_[ends_[degree]++] = v;
    min_key_ = std::min(min_key_, degree);
  }

  // The first current entry of the least degree; kNoId when none is current.
  // current(v, degree): whether v is unmarked and of that updated degree.
  template <class Current>
  uint32_t min(const Current& current) {
    for (; min_key_ < ends_.size(); ++min_key_)
      for (size_t& head = heads_[min_key_]; head < ends_[min_key_]; ++head)
        if (current(entries_[head], min_key_)) return entries_[head];
    return kNoId;
  }

 private:
  std::vector<uint32_t> entries_;  // the lists, degree 0's first
  std::vector<size_t> heads_;      // per degree: the entries before it are stale
  std::vector<size_t> ends_;       // per degree: its list's end
  uint32_t min_key_;               // no current entry has a lesser degree
};

}  // namespace

Partition greedy_partition(const VertexGraph& graph, const std::vector<uint64_t>& targets,
                           uint64_t seed, ChunkedLoops& loops) {
  const uint32_t n = graph.vertex_count(), p = uint32_t(targets.size());
  const uint32_t max_degree = graph.max_degree();
  Partition partition;
  partition.subsets = p;
  std::vector<uint32_t>& subset = partition.vertex_subset;
  assign_touched(subset, n, kNoId, loops);

  std::vector<uint32_t> updated_degree;
  resize_touched(updated_degree, n, loops);
  loops.run(n, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) updated_degree[v] = graph.degree(uint32_t(v));
  });
  // Unmarked vertices with a marked neighbour, by updated degree: where a locked-in subset
  // continues. Kept up to date by mark(), so that finding a seed is O(1) amortised.
  FallingDegrees touched(graph, max_degree, loops);
  auto current = [&](uint32_t v, uint32_t degree) {
    return subset[v] == kNoId && updated_degree[v] == degree;
  };
  // The front being taken in part when the last front overshoots the target.
  BucketQueue partial_front(n, max_degree);
  const std::vector<uint32_t> by_degree = vertices_by_degree(graph, loops);
  size_t by_degree_next = 0;  // vertices before it in by_degree are all marked

  std::optional<SettledFaces> faces;
  if (graph.has_faces()) faces.emplace(graph, loops);
  // Marks v as k's; returns what it adds to the subsets' count: its weight, or by faces the
  // faces it settles.
  auto mark = [&](uint32_t v, uint32_t k) -> uint64_t {
    subset[v] = k;
    for (uint32_t u : graph.neighbours_of(v)) {
      if (subset[u] != kNoId) continue;
      const uint32_t d = --updated_degree[u];
      touched.push(u, d);
      if (!partial_front.empty() && partial_front.contains(u)) partial_front.set_key(u, d);
    }
    return faces ? faces->join(v, k) : graph.weight[v];
  };
  // A seed for a subset that is locked in: the unmarked vertex of minimal updated degree next
  // to the marked region, or when there is none (the region covers whole components), the
  // unmarked vertex of minimal degree (isolated vertices last). kNoId when all are marked.
  auto continuation_seed = [&]() -> uint32_t {
    if (const uint32_t v = touched.min(current); v != kNoId) return v;
    while (by_degree_next < n && subset[by_degree[by_degree_next]] != kNoId) ++by_degree_next;
    return by_degree_next < n ? by_degree[by_degree_next] : kNoId;
  };

  std::vector<uint32_t> members, previous_members;  // of the subset grown, the one before
  std::vector<uint32_t> front, next_front;
  // The front number a vertex was queued for.
  std::vector<uint32_t> queued = filled_touched(n, kNoId, loops);
  uint32_t front_number = 0;
  bool first = true;
  // The last subset takes what remains; the others are grown, each until the subsets so far
  // have counted their targets together (with vertex weights, each reaches its own target
  // and passes it by less than one vertex; by faces, see SettledFaces).
  uint64_t counted = 0, cumulative_target = 0;
  for (uint32_t k = 0; k + 1 < p; ++k) {
    const uint64_t target = targets[k];
    if (target == 0) continue;                // a weight too small to be worth a vertex
    if (!faces) counted = cumulative_target;  // weights: each subset from its own target
    cumulative_target += target;
    members.clear();

    // Start vertex: for the first subset, a vertex of minimal degree (a corner or a boundary
    // of the mesh); for the others, the unmarked neighbour of the previous subset with minimal
    // updated degree (ties to the smallest id), so that subsets follow each other.
    uint32_t start = kNoId;
    if (first) {
      start = first_start_vertex(graph, by_degree, seed, kStartCandidates);
      first = false;
    } else {
      for (uint32_t v : previous_members) {
        for (uint32_t u : graph.neighbours_of(v)) {
          if (subset[u] != kNoId) continue;
          if (start == kNoId || updated_degree[u] < updated_degree[start] ||
              (updated_degree[u] == updated_degree[start] && u < start)) {
            start = u;
          }
        }
      }
      if (start == kNoId) start = continuation_seed();
    }
    if (start == kNoId) break;  // every vertex is taken: the remaining subsets stay empty
    front.assign(1, start);

    // At least one vertex, even when the subsets before passed this one's target too (by
    // faces, one vertex can settle more faces than a small share: a grid cut in as many
    // subsets as vertices).
    auto wants_more = [&] { return counted < cumulative_target || members.empty(); };
    while (wants_more()) {
      if (front.empty()) {
        // Locked in: no unmarked neighbour, still below target. Continue from a new seed
        // (the subset becomes multi-connected) rather than restart the whole partition.
        const uint32_t s = continuation_seed();
        if (s == kNoId) break;  // cannot happen: the targets sum to n; kept for safety
        front.assign(1, s);
      }
      // By faces, the front settles at most 3 per face of its vertices (its weight times 3):
      // counted exactly only where that bound would overshoot.
      uint64_t front_weight = 0;
      for (uint32_t v : front) front_weight += graph.weight[v];
      if (faces && counted + 3 * front_weight > cumulative_target)
        front_weight = faces->gain(front, k);
      else if (faces)
        front_weight *= 3;
      if (counted + front_weight <= cumulative_target) {
        // The whole front joins k. Marked first, so that one pass over each vertex's
        // neighbours both lowers the updated degrees of the unmarked ones (as mark() does; the
        // front's own vertices, marked anyway, need none, and the partial front is empty
        // here) and queues them for the next front: front order, then neighbour order.
        for (uint32_t v : front) subset[v] = k;
        ++front_number;
        next_front.clear();
        for (uint32_t v : front) {
          for (uint32_t u : graph.neighbours_of(v)) {
            if (subset[u] != kNoId) continue;
            touched.push(u, --updated_degree[u]);
            if (queued[u] == front_number) continue;
            queued[u] = front_number;
            next_front.push_back(u);
          }
          counted += faces ? faces->join(v, k) : graph.weight[v];
          members.push_back(v);
        }
        std::swap(front, next_front);
      } else {
        // The front would overshoot: take its vertices of minimal updated degree first
        // (updated as they are taken), which leaves the fewest unmarked vertices cut off.
        for (uint32_t v : front) partial_front.insert(v, updated_degree[v]);
        // (The front's gain exceeds what is missing, so it does not run out; checked anyway.)
        while (wants_more() && !partial_front.empty()) {
          const uint32_t v = partial_front.pop_min();
          counted += mark(v, k);
          members.push_back(v);
        }
        for (uint32_t v : front) {
          if (partial_front.contains(v)) partial_front.remove(v);
        }
        front.clear();
      }
    }
    std::swap(previous_members, members);
  }
  loops.run(n, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v)
      if (subset[v] == kNoId) subset[v] = p - 1;
  });
  return partition;
}

}  // namespace parapm::partition_detail
