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
#include <vector>

#include "partition/partition_internal.h"

namespace parapm::partition_detail {

Partition greedy_partition(const VertexGraph& graph, const std::vector<uint64_t>& targets,
                           uint64_t seed) {
  const uint32_t n = graph.vertex_count(), p = uint32_t(targets.size());
  const uint32_t max_degree = graph.max_degree();
  Partition partition;
  partition.subsets = p;
  std::vector<uint32_t>& subset = partition.vertex_subset;
  subset.assign(n, kNoId);

  std::vector<uint32_t> updated_degree(n);
  for (uint32_t v = 0; v < n; ++v) updated_degree[v] = graph.degree(v);
  // Unmarked vertices with a marked neighbour, by updated degree: where a locked-in subset
  // continues. Kept up to date by mark(), so that finding a seed is O(1) amortised.
  BucketQueue touched(n, max_degree);
  // The front being taken in part when the last front overshoots the target.
  BucketQueue partial_front(n, max_degree);
  const std::vector<uint32_t> by_degree = vertices_by_degree(graph);
  size_t by_degree_next = 0;  // vertices before it in by_degree are all marked

  auto mark = [&](uint32_t v, uint32_t k) {
    subset[v] = k;
    if (touched.contains(v)) touched.remove(v);
    for (uint32_t u : graph.neighbours_of(v)) {
      if (subset[u] != kNoId) continue;
      const uint32_t d = --updated_degree[u];
      if (touched.contains(u)) {
        touched.set_key(u, d);
      } else {
        touched.insert(u, d);
      }
      if (partial_front.contains(u)) partial_front.set_key(u, d);
    }
  };
  // A seed for a subset that is locked in: the unmarked vertex of minimal updated degree next
  // to the marked region, or when there is none (the region covers whole components), the
  // unmarked vertex of minimal degree (isolated vertices last). kNoId when all are marked.
  auto continuation_seed = [&]() -> uint32_t {
    if (!touched.empty()) return touched.min();
    while (by_degree_next < n && subset[by_degree[by_degree_next]] != kNoId) ++by_degree_next;
    return by_degree_next < n ? by_degree[by_degree_next] : kNoId;
  };

  std::vector<uint32_t> members, previous_members;  // of the subset grown, the one before
  std::vector<uint32_t> front, next_front;
  std::vector<uint32_t> queued(n, kNoId);  // the front number a vertex was queued for
  uint32_t front_number = 0;
  bool first = true;
  // The last subset takes what remains; the others are grown.
  for (uint32_t k = 0; k + 1 < p; ++k) {
    const uint64_t target = targets[k];
    if (target == 0) continue;  // a weight too small to be worth a vertex
    members.clear();
    uint64_t taken = 0;  // the members' weights

    // Start vertex: for the first subset, a vertex of minimal degree (a corner or a boundary
    // of the mesh); for the others, the unmarked neighbour of the previous subset with minimal
    // updated degree (ties to the smallest id), so that subsets follow each other.
    uint32_t start = kNoId;
    if (first) {
      start = first_start_vertex(graph, by_degree, seed);
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
    front.assign(1, start);

    while (taken < target) {
      if (front.empty()) {
        // Locked in: no unmarked neighbour, still below target. Continue from a new seed
        // (the subset becomes multi-connected) rather than restart the whole partition.
        const uint32_t s = continuation_seed();
        if (s == kNoId) break;  // cannot happen: the targets sum to n; kept for safety
        front.assign(1, s);
      }
      uint64_t front_weight = 0;
      for (uint32_t v : front) front_weight += graph.weight[v];
      if (taken + front_weight <= target) {
        for (uint32_t v : front) {
          mark(v, k);
          members.push_back(v);
        }
        taken += front_weight;
        ++front_number;
        next_front.clear();
        for (uint32_t v : front) {
          for (uint32_t u : graph.neighbours_of(v)) {
            if (subset[u] != kNoId || queued[u] == front_number) continue;
            queued[u] = front_number;
            next_front.push_back(u);
          }
        }
        std::swap(front, next_front);
      } else {
        // The front would overshoot: take its vertices of minimal updated degree first
        // (updated as they are taken), which leaves the fewest unmarked vertices cut off.
        for (uint32_t v : front) partial_front.insert(v, updated_degree[v]);
        while (taken < target) {
          const uint32_t v = partial_front.pop_min();
          mark(v, k);
          members.push_back(v);
          taken += graph.weight[v];
        }
        for (uint32_t v : front) {
          if (partial_front.contains(v)) partial_front.remove(v);
        }
        front.clear();
      }
    }
    std::swap(previous_members, members);
  }
  for (uint32_t v = 0; v < n; ++v) {
    if (subset[v] == kNoId) subset[v] = p - 1;
  }
  return partition;
}

}  // namespace parapm::partition_detail
