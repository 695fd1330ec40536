// The checks every partition must pass, on drawn and on real meshes alike.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "mesh/mesh.h"
#include "partition/partition.h"

namespace parapm {

// Every vertex in [0, p), subset sizes exactly the targets, every face given to the majority
// subset of its vertices (else the smallest of the three).
inline void expect_valid(const Mesh& mesh, const Partition& partition, uint32_t p,
                         const std::vector<double>& weights = {}) {
  ASSERT_EQ(partition.subsets, p);
  ASSERT_EQ(partition.vertex_subset.size(), mesh.vertex_count());
  ASSERT_EQ(partition.face_subset.size(), mesh.face_count());
  std::vector<uint32_t> sizes(p, 0);
  for (uint32_t s : partition.vertex_subset) {
    ASSERT_LT(s, p);
    ++sizes[s];
  }
  EXPECT_EQ(sizes, partition_targets(uint32_t(mesh.vertex_count()), p, weights));
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
