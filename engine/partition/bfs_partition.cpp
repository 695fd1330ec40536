// The intuitive baseline the greedy algorithm is measured against (Langis 1999 compares with
// it; Ciarlet & Lamour, "An Efficient Low Cost Greedy Graph Partitioning Heuristic", UCLA CAM
// 94-1, discuss why simultaneous growth gives worse cuts): p seeds spread over the mesh, grown
// together, round-robin, one vertex at a time by breadth-first search, each until it reaches
// its target. Growing all subsets at once lets them close in on each other and leave small
// unclaimed pockets, which is what the greedy algorithm avoids.
#include <algorithm>
#include <vector>

#include "partition/partition_internal.h"

namespace parapm::partition_detail {
namespace {

// Seeds, one per subset with a non-zero target: the first by the seed rule, each next one the
// vertex farthest in BFS hops from the seeds chosen so far (a vertex in a component without a
// seed counts as infinitely far; ties to the smallest id; isolated vertices only when nothing
// else is left). Distances are updated by a BFS from each new seed that stops where the
// distance does not improve: O(p |V|) for the farthest-vertex scans plus the BFS work.
std::vector<uint32_t> spread_seeds(const VertexGraph& graph, uint32_t count, uint64_t seed) {
  const uint32_t n = graph.vertex_count();
  ChunkedLoops one_thread;
  const std::vector<uint32_t> by_degree = vertices_by_degree(graph, one_thread);
  std::vector<uint32_t> distance(n, kNoId), queue;
  std::vector<char> chosen(n, 0);
  std::vector<uint32_t> seeds;
  auto add_seed = [&](uint32_t s) {
    seeds.push_back(s);
    chosen[s] = 1;
    distance[s] = 0;
    queue.assign(1, s);
    for (size_t head = 0; head < queue.size(); ++head) {
      const uint32_t v = queue[head];
      for (uint32_t u : graph.neighbours_of(v)) {
        if (distance[u] <= distance[v] + 1) continue;
        distance[u] = distance[v] + 1;
        queue.push_back(u);
      }
    }
  };
  add_seed(first_start_vertex(graph, by_degree, seed, 1));
  while (seeds.size() < count) {
    uint32_t best = kNoId;
    for (int pass = 0; pass < 2 && best == kNoId; ++pass) {
      for (uint32_t v = 0; v < n; ++v) {
        if (chosen[v] || (pass == 0 && graph.degree(v) == 0)) continue;
        if (best == kNoId || distance[v] > distance[best]) best = v;
      }
    }
    add_seed(best);  // exists: count <= n
  }
  return seeds;
}

}  // namespace

Partition bfs_partition(const VertexGraph& graph, const std::vector<uint64_t>& targets,
                        uint64_t seed) {
  const uint32_t n = graph.vertex_count(), p = uint32_t(targets.size());
  Partition partition;
  partition.subsets = p;
  std::vector<uint32_t>& subset = partition.vertex_subset;
  subset.assign(n, kNoId);

  std::vector<uint32_t> growing;  // subsets with a non-zero target, in id order
  for (uint32_t k = 0; k < p; ++k) {
    if (targets[k] > 0) growing.push_back(k);
  }
  const std::vector<uint32_t> seeds = spread_seeds(graph, uint32_t(growing.size()), seed);

  // Each subset's BFS queue holds candidates that may have been taken by another subset since
  // they were queued; they are skipped when popped. Every marked vertex queues its neighbours
  // once, so all queues together see at most 2 |E| pushes.
  std::vector<std::vector<uint32_t>> queue(p);
  std::vector<size_t> head(p, 0);
  std::vector<uint64_t> size(p, 0);  // the members' weights
  auto mark = [&](uint32_t v, uint32_t k) {
    subset[v] = k;
    size[k] += graph.weight[v];
    for (uint32_t u : graph.neighbours_of(v)) {
      if (subset[u] == kNoId) queue[k].push_back(u);
    }
  };
  for (size_t i = 0; i < growing.size(); ++i) mark(seeds[i], growing[i]);

  // Round-robin, one vertex per subset per round. A subset leaves the rotation when it
  // reaches its target or its queue runs dry (its region is enclosed by other subsets).
  std::vector<uint32_t> active;
  for (uint32_t k : growing) {
    if (size[k] < targets[k]) active.push_back(k);
  }
  while (!active.empty()) {
    size_t kept = 0;
    for (uint32_t k : active) {
      uint32_t v = kNoId;
      while (head[k] < queue[k].size()) {
        const uint32_t candidate = queue[k][head[k]++];
        if (subset[candidate] == kNoId) {
          v = candidate;
          break;
        }
      }
      if (v == kNoId) continue;  // enclosed
      mark(v, k);
      if (size[k] < targets[k]) active[kept++] = k;
    }
    active.resize(kept);
  }

  // What no subset reached (components without a seed, enclosed pockets, isolated vertices)
  // goes to the subsets below their targets, in subset order, one component after another in
  // BFS order so that pieces stay connected where they can.
  uint32_t k = 0;
  std::vector<uint32_t> order;
  for (uint32_t start = 0; start < n; ++start) {
    if (subset[start] != kNoId) continue;
    order.assign(1, start);
    subset[start] = kNoId - 1;  // queued
    for (size_t i = 0; i < order.size(); ++i) {
      for (uint32_t u : graph.neighbours_of(order[i])) {
        if (subset[u] != kNoId) continue;
        subset[u] = kNoId - 1;
        order.push_back(u);
      }
    }
    for (uint32_t v : order) {
      while (k + 1 < p && size[k] >= targets[k]) ++k;  // the last subset takes any excess
      subset[v] = k;
      size[k] += graph.weight[v];
    }
  }
  return partition;
}

}  // namespace parapm::partition_detail
