#include "partition/partition_metrics.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "partition/partition_internal.h"
#include "util/error.h"

namespace parapm {
namespace partition_detail {

CutShape cut_shape(const VertexGraph& graph, const std::vector<uint32_t>& vertex_subset,
                   uint32_t p) {
  // Cut edges and components together: union-find over the edges inside a subset.
  const uint32_t n = graph.vertex_count();
  std::vector<uint32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];  // path halving
    return v;
  };
  CutShape shape;
  for (uint32_t v = 0; v < n; ++v) {
    for (uint32_t u : graph.neighbours_of(v)) {
      if (u < v) continue;  // each edge once
      if (vertex_subset[u] != vertex_subset[v]) {
        ++shape.cut_edges;
      } else {
        const uint32_t a = find(u), b = find(v);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
  }
  shape.components.assign(p, 0);
  for (uint32_t v = 0; v < n; ++v) {
    if (find(v) == v) ++shape.components[vertex_subset[v]];
  }
  return shape;
}

}  // namespace partition_detail

PartitionMetrics partition_metrics(const Mesh& mesh, const Partition& partition,
                                   const PartitionOptions& options, double seconds) {
  const uint32_t p = partition.subsets;
  if (partition.vertex_subset.size() != mesh.vertex_count() ||
      partition.face_subset.size() != mesh.face_count()) {
    throw_invalid("partition metrics: the partition does not fit the mesh");
  }
  for (uint32_t s : partition.vertex_subset) {
    if (s >= p) throw_invalid("partition metrics: vertex subset " + std::to_string(s) + " >= p");
  }
  for (uint32_t s : partition.face_subset) {
    if (s >= p) throw_invalid("partition metrics: face subset " + std::to_string(s) + " >= p");
  }
  if (!options.weights.empty() && options.weights.size() != p) {
    throw_invalid("partition metrics: weights do not match p");
  }

  PartitionMetrics metrics;
  metrics.p = p;
  metrics.algorithm = options.algorithm;
  metrics.seconds = seconds;
  metrics.subset_faces.assign(p, 0);
  for (uint32_t s : partition.face_subset) ++metrics.subset_faces[s];
  const double faces = double(mesh.face_count());
  double mean = p ? faces / p : 0, variance = 0;
  for (uint64_t count : metrics.subset_faces) variance += (count - mean) * (count - mean);
  metrics.stddev_faces = p ? std::sqrt(variance / p) : 0;
  uint32_t biggest = 0;
  for (uint32_t k = 0; k < p; ++k) {
    if (metrics.subset_faces[k] > metrics.subset_faces[biggest]) biggest = k;
  }
  metrics.biggest_faces = p ? metrics.subset_faces[biggest] : 0;
  if (options.weights.empty()) {
    metrics.ideal_faces = mean;
  } else {
    const double sum = std::accumulate(options.weights.begin(), options.weights.end(), 0.0);
    metrics.ideal_faces = faces * options.weights[biggest] / sum;
  }

  const auto& vs = partition.vertex_subset;
  for (const Triangle& face : mesh.faces) {
    if (vs[face[0]] != vs[face[1]] || vs[face[0]] != vs[face[2]]) ++metrics.cut_faces;
  }

  const partition_detail::CutShape shape = partition_detail::cut_shape(
      partition_detail::build_vertex_graph(mesh), partition.vertex_subset, p);
  metrics.cut_edges = shape.cut_edges;
  metrics.components = shape.components;
  return metrics;
}

}  // namespace parapm
