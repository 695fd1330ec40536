// The parts shared by the partitioning algorithms, and partition_mesh(), which checks the
// arguments, computes the targets, runs the chosen algorithm and assigns the faces.
#include "partition/partition.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "partition/partition_internal.h"
#include "util/error.h"
#include "util/fresh_pages.h"
#include "util/zeroed_array.h"

namespace parapm {
namespace partition_detail {

uint32_t VertexGraph::max_degree() const {
  uint32_t result = 0;
  for (uint32_t v = 0; v < vertex_count(); ++v) result = std::max(result, degree(v));
  return result;
}

VertexGraph build_vertex_graph(const Mesh& mesh) {
  ChunkedLoops one_thread;
  return build_vertex_graph(mesh, one_thread, false);
}

VertexGraph build_vertex_graph(const Mesh& mesh, ChunkedLoops& loops, bool with_faces) {
  const size_t n = mesh.vertex_count();
  // The first face with a corner out of range, as one pass in face order finds it.
  std::vector<std::pair<size_t, VertexId>> bad(loops.ranges(mesh.faces.size()), {SIZE_MAX, 0});
  loops.run_indexed(mesh.faces.size(), [&](size_t range, size_t begin, size_t end) {
    for (size_t f = begin; f < end && bad[range].first == SIZE_MAX; ++f)
      for (VertexId v : mesh.faces[f])
        if (v >= n) {
          bad[range] = {f, v};
          break;
        }
  });
  for (const auto& [f, v] : bad)
    if (f != SIZE_MAX)
      throw_invalid("face " + std::to_string(f) + " has vertex " + std::to_string(v) +
                    " but the mesh has " + std::to_string(n) + " vertices");

  // Each range of vertices lists its vertices' neighbours from their corners, in face order:
  // each corner gives its vertex two (possibly repeated) neighbours, kept at their first
  // occurrence (no sorting or hashing); the ranges' lists are joined in vertex order. With
  // `with_faces`, each vertex's faces too, in increasing order.
  auto vertex_of = [&](size_t corner) { return mesh.faces[corner / 3][corner % 3]; };
  const size_t corners = 3 * mesh.faces.size();
  const auto corners_of_range = items_of_ranges(loops, corners, n, vertex_of);
  struct Lists {
    std::vector<size_t> offsets;  // per vertex of the range, then its end
    std::vector<uint32_t> neighbours;
    std::vector<size_t> face_offsets;
    std::vector<uint32_t> face_ids;
  };
  std::vector<Lists> lists(loops.ranges(n));
  loops.run_indexed(n, [&](size_t range, size_t first, size_t last) {
    const RangeItems mine(corners_of_range, range, corners);
    Lists& out = lists[range];
    // listed[u] == v + 1: u is already among v's neighbours (a stamp per vertex of the mesh,
    // zeroed pages: a range touches its neighbours' only). A hub of a million faces costs its
    // corners, not their square.
    ZeroedArray<uint32_t> listed;
    listed.assign_zeroed(n);
    std::vector<size_t> start(last - first + 1, 0);
    for (size_t j = 0; j < mine.size(); ++j) start[vertex_of(mine[j]) - first + 1] += 2;
    for (size_t v = 0; v < last - first; ++v) start[v + 1] += start[v];
    std::vector<uint32_t> around(start.back());
    std::vector<size_t> fill(start.begin(), start.end() - 1);
    for (size_t j = 0; j < mine.size(); ++j) {
      const Triangle& face = mesh.faces[mine[j] / 3];
      const size_t c = mine[j] % 3;
      const size_t v = face[c] - first;
      around[fill[v]++] = face[(c + 1) % 3];
      around[fill[v]++] = face[(c + 2) % 3];
    }
    out.offsets.resize(last - first + 1);
    out.neighbours.reserve(around.size() / 2 + 16);  // closed manifolds: each edge twice
    for (size_t v = 0; v < last - first; ++v) {
      out.offsets[v] = out.neighbours.size();
      for (size_t i = start[v]; i < start[v + 1]; ++i) {
        const uint32_t u = around[i];
        const uint32_t stamp = uint32_t(first + v + 1);
        if (u == first + v || listed[u] == stamp) continue;  // a repeated corner, or listed
        listed[u] = stamp;
        out.neighbours.push_back(u);
      }
    }
    out.offsets[last - first] = out.neighbours.size();
    if (!with_faces) return;
    out.face_offsets.resize(last - first + 1);
    for (size_t v = 0; v <= last - first; ++v) out.face_offsets[v] = start[v] / 2;
    out.face_ids.resize(start.back() / 2);
    for (size_t v = 0; v < last - first; ++v) fill[v] = start[v] / 2;
    for (size_t j = 0; j < mine.size(); ++j)
      out.face_ids[fill[vertex_of(mine[j]) - first]++] = mine[j] / 3;
  });
  // The ranges' lists joined in order, each range copying its own (the same ranges as above).
  std::vector<size_t> neighbours_before(lists.size() + 1, 0), faces_before(lists.size() + 1, 0);
  for (size_t range = 0; range < lists.size(); ++range) {
    neighbours_before[range + 1] = neighbours_before[range] + lists[range].neighbours.size();
    faces_before[range + 1] = faces_before[range] + lists[range].face_ids.size();
  }
  VertexGraph graph;
  resize_touched(graph.offsets, n + 1, loops);
  if (with_faces) resize_touched(graph.face_offsets, n + 1, loops);
  resize_touched(graph.neighbours, neighbours_before.back(), loops);
  resize_touched(graph.face_ids, faces_before.back(), loops);
  loops.run_indexed(n, [&](size_t range, size_t first, size_t) {
    const Lists& out = lists[range];
    for (size_t i = 0; i + 1 < out.offsets.size(); ++i) {
      graph.offsets[first + i] = neighbours_before[range] + out.offsets[i];
      if (with_faces) graph.face_offsets[first + i] = faces_before[range] + out.face_offsets[i];
    }
    std::copy(out.neighbours.begin(), out.neighbours.end(),
              graph.neighbours.begin() + ptrdiff_t(neighbours_before[range]));
    std::copy(out.face_ids.begin(), out.face_ids.end(),
              graph.face_ids.begin() + ptrdiff_t(faces_before[range]));
  });
  graph.offsets[n] = graph.neighbours.size();
  if (with_faces) {
    graph.face_offsets[n] = graph.face_ids.size();
    graph.face_count = uint32_t(mesh.face_count());
  }
  return graph;
}

BucketQueue::BucketQueue(uint32_t items, uint32_t max_key)
    : head_(size_t(max_key) + 1, kNoId), tail_(size_t(max_key) + 1, kNoId), min_key_(max_key + 1) {
  next_.assign_zeroed(items);
  prev_.assign_zeroed(items);
  key_plus_one_.assign_zeroed(items);
}

void BucketQueue::insert(uint32_t item, uint32_t key) {
  key_plus_one_[item] = key + 1;
  next_[item] = kNoId;
  prev_[item] = tail_[key];
  if (tail_[key] != kNoId) {
    next_[tail_[key]] = item;
  } else {
    head_[key] = item;
  }
  tail_[key] = item;
  min_key_ = std::min(min_key_, key);
  ++size_;
}

void BucketQueue::remove(uint32_t item) {
  const uint32_t key = key_plus_one_[item] - 1;
  if (prev_[item] != kNoId) {
    next_[prev_[item]] = next_[item];
  } else {
    head_[key] = next_[item];
  }
  if (next_[item] != kNoId) {
    prev_[next_[item]] = prev_[item];
  } else {
    tail_[key] = prev_[item];
  }
  key_plus_one_[item] = 0;
  --size_;
}

uint32_t BucketQueue::min() {
  if (size_ == 0) return kNoId;
  while (head_[min_key_] == kNoId) ++min_key_;  // terminates: some bucket is occupied
  return head_[min_key_];
}

uint32_t BucketQueue::pop_min() {
  const uint32_t item = min();
  if (item != kNoId) remove(item);
  return item;
}

std::vector<uint32_t> vertices_by_degree(const VertexGraph& graph, ChunkedLoops& loops) {
  // Counting sort; degree 0 is given the key past the maximum so that it sorts last.
  const uint32_t n = graph.vertex_count(), max_degree = graph.max_degree();
  auto key = [&](uint32_t v) {
    const uint32_t d = graph.degree(v);
    return d == 0 ? max_degree + 1 : d;
  };
  std::vector<size_t> start(size_t(max_degree) + 3, 0);
  for (uint32_t v = 0; v < n; ++v) ++start[key(v) + 1];
  for (size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
  std::vector<uint32_t> order;
  resize_touched(order, n, loops);
  for (uint32_t v = 0; v < n; ++v) order[start[key(v)]++] = v;
  return order;
}

uint32_t first_start_vertex(const VertexGraph& graph, const std::vector<uint32_t>& by_degree,
                            uint64_t seed, size_t candidates) {
  const uint32_t min_degree = graph.degree(by_degree.front());
  size_t count = 0;
  while (count < by_degree.size() && graph.degree(by_degree[count]) == min_degree) ++count;
  // Where few vertices have the least degree (a CAD part's corners, a scan's odd vertices: the
  // bunny, fandisk, gears), most seeds would start at the same one and draw the same partition:
  // the next degrees join them, a degree at a time, until there are `candidates`.
  while (count < candidates && count < by_degree.size() && graph.degree(by_degree[count]) > 0) {
    const uint32_t next_degree = graph.degree(by_degree[count]);
    while (count < by_degree.size() && graph.degree(by_degree[count]) == next_degree) ++count;
  }
  return by_degree[seed % count];
}

void assign_faces(const Mesh& mesh, Partition& partition, ChunkedLoops& loops) {
  // Each face is simplified by exactly one worker. Giving it to the subset that owns the
  // majority of its vertices keeps it with the worker that holds most of its edges (two of
  // its three edges lie inside that subset), so fewer faces wait for the border pass. When
  // the three vertices are in three subsets there is no majority: the smallest subset id
  // wins, which does not depend on which corner happens to be listed first.
  const auto& vs = partition.vertex_subset;
  resize_touched(partition.face_subset, mesh.faces.size(), loops);
  loops.run(mesh.faces.size(), [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      const uint32_t a = vs[mesh.faces[f][0]], b = vs[mesh.faces[f][1]], c = vs[mesh.faces[f][2]];
      uint32_t owner;
      if (a == b || a == c) {
        owner = a;
      } else if (b == c) {
        owner = b;
      } else {
        owner = std::min({a, b, c});
      }
      partition.face_subset[f] = owner;
    }
  });
}

}  // namespace partition_detail

namespace partition_detail {

std::vector<uint64_t> share_targets(uint64_t vertices, uint32_t p,
                                    const std::vector<double>& weights) {
  if (p < 1 || p > kMaxPartitionSubsets) {
    throw_invalid("partition: p must be from 1 to " + std::to_string(kMaxPartitionSubsets) +
                  ", got " + std::to_string(p));
  }
  if (!weights.empty() && weights.size() != p) {
    throw_invalid("partition: " + std::to_string(weights.size()) +
                  " weights given for p = " + std::to_string(p) + " subsets");
  }
  double sum = 0;
  for (size_t i = 0; i < weights.size(); ++i) {
    if (!std::isfinite(weights[i]) || !(weights[i] > 0)) {
      throw_invalid("partition: weight " + std::to_string(i) + " is " + std::to_string(weights[i]) +
                    ", weights must be positive and finite");
    }
    sum += weights[i];
  }
  if (!std::isfinite(sum)) throw_invalid("partition: the weights' sum is not finite");
  // Largest remainder: floor of each exact share, then one more vertex to the subsets with
  // the largest fractional parts (ties to the lower subset) until the sizes sum to `vertices`.
  std::vector<uint64_t> targets(p);
  std::vector<double> remainder(p);
  uint64_t given = 0;
  for (uint32_t i = 0; i < p; ++i) {
    const double share =
        weights.empty() ? double(vertices) / p : double(vertices) * (weights[i] / sum);
    const double whole = std::min(std::floor(share), double(vertices));
    targets[i] = uint64_t(whole);
    remainder[i] = share - whole;
    given += targets[i];
  }
  std::vector<uint32_t> order(p);
  for (uint32_t i = 0; i < p; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t x, uint32_t y) { return remainder[x] > remainder[y]; });
  // Rounding can leave `given` a little off either way; correct one vertex at a time.
  for (size_t k = 0; given < vertices; k = (k + 1) % p, ++given) ++targets[order[k]];
  for (size_t k = p; given > vertices;) {
    k = (k + p - 1) % p;  // take back from the smallest remainders first
    if (targets[order[k]] > 0) {
      --targets[order[k]];
      --given;
    }
  }
  return targets;
}

}  // namespace partition_detail

std::vector<uint32_t> partition_targets(uint32_t vertices, uint32_t p,
                                        const std::vector<double>& weights) {
  const std::vector<uint64_t> shares = partition_detail::share_targets(vertices, p, weights);
  return std::vector<uint32_t>(shares.begin(), shares.end());
}

namespace {

// partition_mesh's checks of its arguments, before any work.
void check_partition_arguments(const Mesh& mesh, uint32_t p, const PartitionOptions& options) {
  if (mesh.vertex_count() >= kNoId) throw_invalid("partition: too many vertices");
  const uint32_t n = uint32_t(mesh.vertex_count());
  partition_targets(n, p, options.weights);  // validates p and the weights
  if (p > n) {
    throw_invalid("partition: p = " + std::to_string(p) + " subsets but the mesh has only " +
                  std::to_string(n) + " vertices");
  }
  if (options.algorithm != "greedy" && options.algorithm != "bfs") {
    throw_invalid("partition: unknown algorithm '" + options.algorithm +
                  "' (expected greedy or bfs)");
  }
}

}  // namespace

PartitionGraph::PartitionGraph(const Mesh& mesh, Balance balance, ChunkedLoops* loops)
    : mesh_(mesh), balance_(balance) {
  using namespace partition_detail;
  if (mesh.vertex_count() >= kNoId) throw_invalid("partition: too many vertices");
  const uint32_t n = uint32_t(mesh.vertex_count());
  ChunkedLoops one_thread;
  const bool by_faces = balance == Balance::kFaces;
  ChunkedLoops& chunks = loops ? *loops : one_thread;
  auto graph = std::make_unique<VertexGraph>(build_vertex_graph(mesh, chunks, by_faces));
  resize_touched(graph->weight, n, chunks, by_faces ? 0u : 1u);
  if (by_faces)  // a vertex counts its faces
    chunks.run(n, [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v)
        graph->weight[v] = uint32_t(graph->face_offsets[v + 1] - graph->face_offsets[v]);
    });
  graph_ = std::move(graph);
}

PartitionGraph::~PartitionGraph() = default;

Partition PartitionGraph::draw(uint32_t p, const PartitionOptions& options) const {
  using namespace partition_detail;
  check_partition_arguments(mesh_, p, options);
  if (options.balance != balance_)
    throw_invalid("partition: the graph was built for the other balance");
  uint64_t total = 0;
  for (uint32_t w : graph_->weight) total += w;
  const std::vector<uint64_t> targets = share_targets(total, p, options.weights);
  ChunkedLoops one_thread;
  ChunkedLoops& loops = options.loops ? *options.loops : one_thread;
  Partition partition = options.algorithm == "greedy"
                            ? greedy_partition(*graph_, targets, options.seed, loops)
                            : bfs_partition(*graph_, targets, options.seed);
  if (options.refine) refine_partition(*graph_, targets, partition);
  assign_faces(mesh_, partition, loops);
  return partition;
}

Partition partition_mesh(const Mesh& mesh, uint32_t p, const PartitionOptions& options) {
  check_partition_arguments(mesh, p, options);
  return PartitionGraph(mesh, options.balance, options.loops).draw(p, options);
}

}  // namespace parapm
