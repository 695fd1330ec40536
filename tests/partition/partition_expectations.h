// The checks every partition must pass, on drawn and on real meshes alike.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "mesh/mesh.h"
#include "partition/partition.h"
#include "partition/partition_internal.h"

namespace parapm {

// Every vertex in [0, p), subset sizes as the targets ask, every face given to the majority
// subset of its vertices (else the smallest of the three). `grown_together`: the BFS
// baseline, whose subsets grow at once and count face corners; else the greedy algorithm,
// which grows one subset after the other and counts faces.
inline void expect_valid(const Mesh& mesh, const Partition& partition, uint32_t p,
                         const std::vector<double>& weights = {},
                         Balance balance = Balance::kVertices, bool grown_together = false) {
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
    std::vector<uint32_t> corners(mesh.vertex_count(), 0);
    for (const Triangle& face : mesh.faces)
      for (VertexId v : face) ++corners[v];
    const uint32_t heaviest = *std::max_element(corners.begin(), corners.end());
    // Targets in face corners, 3 per face.
    const auto targets =
        partition_detail::share_targets(3 * uint64_t(mesh.face_count()), p, weights);
    if (grown_together) {
      // Each subset but the last reaches its share of the face corners and passes it by less
      // than one vertex's faces; the last takes the rest. A subset enclosed by others before
      // its target takes the pockets they left: short by up to what they passed theirs by.
      std::vector<uint64_t> taken(p, 0);
      for (VertexId v = 0; v < mesh.vertex_count(); ++v)
        taken[partition.vertex_subset[v]] += corners[v];
      for (uint32_t k = 0; k + 1 < p; ++k) {
        if (targets[k] == 0) continue;
        EXPECT_GE(taken[k] + uint64_t(p - 1) * heaviest, targets[k]) << "subset " << k;
        EXPECT_LT(taken[k], targets[k] + heaviest) << "subset " << k;
      }
    } else {
      // Subsets 0 ... k together own at least their targets' faces and pass them by less than
      // one vertex's faces, plus the faces split three ways whose third corner came later
      // (they go to the smallest subset; bounded here by all three-way faces of 0 ... k).
      std::vector<uint64_t> owned(p, 0), three_way(p, 0);
      for (size_t f = 0; f < mesh.face_count(); ++f) {
        const auto& face = mesh.faces[f];
        const uint32_t a = partition.vertex_subset[face[0]], b = partition.vertex_subset[face[1]],
                       c = partition.vertex_subset[face[2]];
        ++owned[partition.face_subset[f]];
        if (a != b && b != c && a != c) ++three_way[std::min({a, b, c})];
      }
      uint64_t cumulative_target = 0, cumulative_owned = 0, cumulative_three_way = 0;
      for (uint32_t k = 0; k + 1 < p; ++k) {
        cumulative_target += targets[k];
        cumulative_owned += owned[k];
        cumulative_three_way += three_way[k];
        EXPECT_GE(3 * cumulative_owned, cumulative_target) << "subsets 0 ... " << k;
        EXPECT_LT(cumulative_owned, (cumulative_target + 2) / 3 + heaviest + cumulative_three_way)
            << "subsets 0 ... " << k;
      }
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
