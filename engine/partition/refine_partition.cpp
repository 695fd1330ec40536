// Refinement of a partition (beyond Langis 1999): boundary vertices move to the neighbouring
// subset that holds more of their edges (a greedy, Kernighan-Lin / Fiduccia-Mattheyses style
// gain, one vertex at a time), and stray components of a subset (all but its largest) move
// whole to the neighbour they touch most, both only while every subset stays within
// [0.97, 1.03] x its target (inside the partitioner's 5% bound). Fewer cut edges mean less border
// left for the later rounds of the parallel build; fewer components mean compact subsets. Each
// sweep is O(|E|). A vertex that moves can split its old subset, and a stray may find no room
// to go: when the result has more cut edges or more components than the partition it started
// from (seen on two meshes of ../shared/meshes, one component more), that partition is kept.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "partition/partition_internal.h"

namespace parapm::partition_detail {
namespace {

// Loads count face corners (or vertices); faces follow them closely but not exactly (a cut
// face goes to its majority), so the refiner keeps 2% of the 5% bound in hand.
constexpr double kUpper = 1.03;
constexpr double kLower = 0.97;
constexpr int kSweeps = 4;

class Refiner {
 public:
  Refiner(const VertexGraph& graph, const std::vector<uint64_t>& targets, Partition& partition)
      : graph_(graph), subset_(partition.vertex_subset), p_(partition.subsets), load_(p_, 0) {
    for (uint32_t k = 0; k < p_; ++k) {
      upper_.push_back(uint64_t(std::floor(kUpper * double(targets[k]))));
      lower_.push_back(uint64_t(std::ceil(kLower * double(targets[k]))));
    }
    for (uint32_t v = 0; v < graph_.vertex_count(); ++v) load_[subset_[v]] += graph_.weight[v];
  }

  void run() {
    merge_strays();
    for (int sweep = 0; sweep < kSweeps; ++sweep)
      if (!move_boundary_vertices()) break;
    merge_strays();
  }

 private:
  // Whether `weight` can leave `from` for `to` with both staying within their bounds.
  bool fits(uint32_t from, uint32_t to, uint64_t weight) const {
    return load_[to] + weight <= upper_[to] && load_[from] >= lower_[from] + weight;
  }

  void move(uint32_t v, uint32_t to) {
    load_[subset_[v]] -= graph_.weight[v];
    load_[to] += graph_.weight[v];
    subset_[v] = to;
  }

  // One pass over the vertices in id order; true when a vertex moved.
  bool move_boundary_vertices() {
    bool moved = false;
    std::vector<uint32_t> count(p_, 0);
    std::vector<uint32_t> touched;
    for (uint32_t v = 0; v < graph_.vertex_count(); ++v) {
      const uint32_t a = subset_[v];
      touched.clear();
      for (uint32_t u : graph_.neighbours_of(v)) {
        if (count[subset_[u]]++ == 0) touched.push_back(subset_[u]);
      }
      uint32_t best = a;
      for (uint32_t k : touched)
        if (k != a &&
            (count[k] > count[best] || (count[k] == count[best] && best != a && k < best)))
          best = k;
      const uint32_t gain_to = count[best], stay = count[a];
      for (uint32_t k : touched) count[k] = 0;
      if (best != a && gain_to > stay && fits(a, best, graph_.weight[v])) {
        move(v, best);
        moved = true;
      }
    }
    return moved;
  }

  // Every component of a subset but its largest goes whole to the neighbouring subset it
  // shares the most edges with, when the bounds allow.
  void merge_strays() {
    const uint32_t n = graph_.vertex_count();
    std::vector<uint32_t> component(n, kNoId);
    std::vector<std::vector<uint32_t>> members;  // per component
    std::vector<uint32_t> owner;                 // per component, its subset
    std::vector<uint32_t> stack;
    for (uint32_t s = 0; s < n; ++s) {
      if (component[s] != kNoId) continue;
      const uint32_t c = uint32_t(members.size());
      members.emplace_back();
      owner.push_back(subset_[s]);
      component[s] = c;
      stack.assign(1, s);
      while (!stack.empty()) {
        const uint32_t v = stack.back();
        stack.pop_back();
        members[c].push_back(v);
        for (uint32_t u : graph_.neighbours_of(v)) {
          if (component[u] != kNoId || subset_[u] != subset_[s]) continue;
          component[u] = c;
          stack.push_back(u);
        }
      }
    }
    // The largest component (by weight, ties to the first) of each subset stays.
    std::vector<uint32_t> main_component(p_, kNoId);
    std::vector<uint64_t> weight(members.size(), 0);
    for (uint32_t c = 0; c < members.size(); ++c) {
      for (uint32_t v : members[c]) weight[c] += graph_.weight[v];
      uint32_t& m = main_component[owner[c]];
      if (m == kNoId || weight[c] > weight[m]) m = c;
    }
    std::vector<uint32_t> count(p_, 0);
    std::vector<uint32_t> touched;
    for (uint32_t c = 0; c < members.size(); ++c) {
      if (main_component[owner[c]] == c) continue;
      touched.clear();
      for (uint32_t v : members[c])
        for (uint32_t u : graph_.neighbours_of(v))
          if (subset_[u] != owner[c] && count[subset_[u]]++ == 0) touched.push_back(subset_[u]);
      uint32_t best = kNoId;
      for (uint32_t k : touched)
        if (best == kNoId || count[k] > count[best] || (count[k] == count[best] && k < best))
          best = k;
      for (uint32_t k : touched) count[k] = 0;
      if (best == kNoId || !fits(owner[c], best, weight[c])) continue;  // a whole component
      for (uint32_t v : members[c]) move(v, best);
    }
  }

  const VertexGraph& graph_;
  std::vector<uint32_t>& subset_;
  uint32_t p_;
  std::vector<uint64_t> load_, upper_, lower_;
};

}  // namespace

void refine_partition(const VertexGraph& graph, const std::vector<uint64_t>& targets,
                      Partition& partition) {
  const std::vector<uint32_t> before = partition.vertex_subset;
  auto pieces = [](const CutShape& shape) {
    return std::accumulate(shape.components.begin(), shape.components.end(), uint64_t(0));
  };
  const CutShape start = cut_shape(graph, before, partition.subsets);
  Refiner(graph, targets, partition).run();
  const CutShape end = cut_shape(graph, partition.vertex_subset, partition.subsets);
  if (end.cut_edges > start.cut_edges || pieces(end) > pieces(start))
    partition.vertex_subset = before;
}

}  // namespace parapm::partition_detail
