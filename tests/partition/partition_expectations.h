// The checks every partition must pass, on drawn and on real meshes alike.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "mesh/mesh.h"
#include "partition/partition.h"
#include "partition/partition_internal.h"

namespace parapm {

// Every vertex in [0, p), subset sizes exactly the targets, every face given to the majority
// subset of its vertices (else the smallest of the three).
inline void expect_valid(const Mesh& mesh, const Partition& partition, uint32_t p,
                         const std::vector<double>& weights = {},
                         Balance balance = Balance::kVertices) {
  ASSERT_EQ(partition.subsets, p);
  ASSERT_EQ(partition.vertex_subset.size(), mesh.vertex_count());
  ASSERT_EQ(partition.face_subset.size(), mesh.face_count());
  std::vector<uint32_t> sizes(p, 0);
  for (uint32_t s : partition.vertex_subset) {
    ASSERT_LT(s, p);
    ++sizes[s];
  }
  if (balance == Balance::kVertices) {
    EXPECT_EQ(sizes, partition_targets(uint32_t(mesh.vertex_count()), p, weights));
  } else {
    // Each subset but the last reaches its share of the face corners and passes it by less
    // than one vertex's faces; the last takes the rest.
    std::vector<uint32_t> corners(mesh.vertex_count(), 0);
    for (const Triangle& face : mesh.faces)
      for (VertexId v : face) ++corners[v];
    const uint32_t heaviest = *std::max_element(corners.begin(), corners.end());
    std::vector<uint64_t> taken(p, 0);
    for (VertexId v = 0; v < mesh.vertex_count(); ++v)
      taken[partition.vertex_subset[v]] += corners[v];
    const auto targets =
        partition_detail::share_targets(3 * uint64_t(mesh.face_count()), p, weights);
    for (uint32_t k = 0; k + 1 < p; ++k) {
      if (targets[k] == 0) continue;
      EXPECT_GE(taken[k], targets[k]) << "subset " << k;
      EXPECT_LT(taken[k], targets[k] + heaviest) << "subset " << k;
    }
  }
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    // The face rule: the majority subset of its vertices, else the smallest.
    const auto& face = mesh.faces[f];
    const uint32_t a = partition.vertex_subset[face[0]], b = partition.vertex_subset[face[1]],
                   c = partition.vertex_subset[face[2]];
    const uint32_t expected = (a == b || a == c) ? a : b == c ? b : std::min({a, b, c});
    EXPECT_EQ(partition.face_subset[f], expected) << "face " << f;
  }
}

}  // namespace parapm
