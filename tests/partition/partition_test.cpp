// partition_mesh() on tiny meshes drawn below, with exact expectations, and its argument
// checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "drawn_meshes.h"
#include "mesh/mesh.h"
#include "partition/partition.h"
#include "partition/partition_internal.h"
#include "partition/partition_metrics.h"
#include "partition_expectations.h"
#include "util/error.h"

namespace parapm {
namespace {

using Subsets = std::vector<uint32_t>;

PartitionOptions options(const char* algorithm, uint64_t seed = 1,
                         std::vector<double> weights = {}) {
  PartitionOptions result;
  result.algorithm = algorithm;
  result.seed = seed;
  result.weights = std::move(weights);
  // The drawn meshes' expectations count vertices; face balance is tested on real meshes.
  result.balance = Balance::kVertices;
  return result;
}

Mesh make_mesh(uint32_t vertices, std::vector<Triangle> faces) {
  Mesh mesh;
  for (uint32_t v = 0; v < vertices; ++v) mesh.positions.push_back({double(v), 0, 0});
  mesh.faces = std::move(faces);
  return mesh;
}

// A strip of 8 faces:
//   0---1---2---3---4
//   | \ | \ | \ | \ |
//   5---6---7---8---9
Mesh strip() {
  std::vector<Triangle> faces;
  for (uint32_t i = 0; i < 4; ++i) {
    faces.push_back({i, i + 5, i + 6});
    faces.push_back({i, i + 6, i + 1});
  }
  return make_mesh(10, faces);
}

// Two triangles that share nothing, and (with_isolated) a vertex that no face uses.
//   0       3
//   | \     | \        6
//   1---2   4---5
Mesh two_triangles(bool with_isolated) {
  return make_mesh(with_isolated ? 7 : 6, {{0, 1, 2}, {3, 4, 5}});
}

// An n x n grid of vertices (id = row * n + column), each square split by its diagonal from
// the top-left corner: 2 (n-1)^2 faces.
Mesh grid(uint32_t n) {
  std::vector<Triangle> faces;
  for (uint32_t r = 0; r + 1 < n; ++r) {
    for (uint32_t c = 0; c + 1 < n; ++c) {
      const uint32_t v = r * n + c;
      faces.push_back({v, v + n, v + n + 1});
      faces.push_back({v, v + n + 1, v + 1});
    }
  }
  return make_mesh(n * n, faces);
}

TEST(PartitionTargets, EqualWeightsSplitTheRemainderToTheLowerSubsets) {
  EXPECT_EQ(partition_targets(10, 3, {}), (Subsets{4, 3, 3}));
  EXPECT_EQ(partition_targets(10, 1, {}), (Subsets{10}));
  EXPECT_EQ(partition_targets(7, 2, {}), (Subsets{4, 3}));
}

TEST(PartitionTargets, WeightsGiveProportionalShares) {
  EXPECT_EQ(partition_targets(10, 4, {1, 2, 3, 4}), (Subsets{1, 2, 3, 4}));
  EXPECT_EQ(partition_targets(100, 4, {1, 2, 3, 4}), (Subsets{10, 20, 30, 40}));
  // 11 * (1/6, 2/6, 3/6) = 1.83, 3.67, 5.5: floors 1, 3, 5, remainders .83, .67, .5.
  EXPECT_EQ(partition_targets(11, 3, {1, 2, 3}), (Subsets{2, 4, 5}));
  // A share that rounds to no vertex leaves its subset empty.
  EXPECT_EQ(partition_targets(4, 2, {1, 1000}), (Subsets{0, 4}));
}

TEST(PartitionTargets, RejectsBadArguments) {
  EXPECT_THROW(partition_targets(10, 0, {}), Error);
  EXPECT_THROW(partition_targets(1000, 257, {}), Error);
  EXPECT_THROW(partition_targets(10, 2, {1}), Error);
  EXPECT_THROW(partition_targets(10, 2, {1, 0}), Error);
  EXPECT_THROW(partition_targets(10, 2, {1, -1}), Error);
  EXPECT_THROW(partition_targets(10, 2, {1, std::nan("")}), Error);
  EXPECT_THROW(partition_targets(10, 2, {1, std::numeric_limits<double>::infinity()}), Error);
  EXPECT_NO_THROW(partition_targets(1000, 256, {}));
}

TEST(PartitionMesh, RejectsBadArguments) {
  const Mesh mesh = strip();
  try {
    partition_mesh(mesh, 11, options("greedy"));
    FAIL() << "p larger than the vertex count was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("only 10 vertices"), std::string::npos) << e.what();
  }
  EXPECT_THROW(partition_mesh(mesh, 0, options("greedy")), Error);
  EXPECT_THROW(partition_mesh(mesh, 2, options("metis")), Error);
  EXPECT_THROW(partition_mesh(mesh, 2, options("greedy", 1, {1, 2, 3})), Error);
  Mesh broken = mesh;
  broken.faces[3][1] = 10;
  broken.faces[5][0] = 12;
  EXPECT_THROW(partition_mesh(broken, 2, options("greedy")), Error);
  // In chunks too, naming the first face, as one pass does.
  ChunkedLoops loops(4, 2, 1);
  PartitionOptions chunked = options("greedy");
  chunked.loops = &loops;
  try {
    partition_mesh(broken, 2, chunked);
    FAIL() << "a corner out of range was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("face 3 has vertex 10"), std::string::npos) << e.what();
  }
  EXPECT_THROW(partition_mesh(Mesh{}, 1, options("greedy")), Error);
}

TEST(PartitionMesh, PIsOneGivesEverythingToSubsetZero) {
  for (const char* algorithm : {"greedy", "bfs"}) {
    const Mesh mesh = grid(4);
    const Partition partition = partition_mesh(mesh, 1, options(algorithm));
    expect_valid(mesh, partition, 1);
    EXPECT_EQ(partition.vertex_subset, Subsets(16, 0));
    EXPECT_EQ(partition.face_subset, Subsets(18, 0));
  }
}

TEST(PartitionMesh, PEqualToTheVertexCountGivesOneVertexEach) {
  for (const char* algorithm : {"greedy", "bfs"}) {
    const Mesh mesh = strip();
    const Partition partition = partition_mesh(mesh, 10, options(algorithm));
    expect_valid(mesh, partition, 10);
  }
}

TEST(GreedyPartition, StripSplitsIntoLeftAndRightHalves) {
  // Minimal degree 2: vertices 4 and 5; seed 1 picks the second, 5. Fronts from 5: {5},
  // {0, 6}, {1, 7} -> 5 vertices, the target. The last subset takes the rest.
  const Mesh mesh = strip();
  const Partition partition = partition_mesh(mesh, 2, options("greedy"));
  expect_valid(mesh, partition, 2);
  EXPECT_EQ(partition.vertex_subset, (Subsets{0, 0, 1, 1, 1, 0, 0, 0, 1, 1}));
  // Face (1, 7, 2) has two vertices in subset 0; (2, 7, 8) two in subset 1.
  EXPECT_EQ(partition.face_subset, (Subsets{0, 0, 0, 0, 1, 1, 1, 1}));
  const PartitionMetrics metrics = partition_metrics(mesh, partition);
  EXPECT_EQ(metrics.subset_faces, (std::vector<uint64_t>{4, 4}));
  EXPECT_EQ(metrics.cut_edges, 3u);  // 1-2, 7-2, 7-8
  EXPECT_EQ(metrics.cut_faces, 2u);
  EXPECT_EQ(metrics.components, (Subsets{1, 1}));
  EXPECT_EQ(metrics.biggest_faces, 4u);
  EXPECT_DOUBLE_EQ(metrics.ideal_faces, 4.0);
  EXPECT_DOUBLE_EQ(metrics.stddev_faces, 0.0);

  // Seed 0 picks vertex 4: the right half first ({4}, {3, 9}, {2, 8}).
  const Partition mirrored = partition_mesh(mesh, 2, options("greedy", 0));
  EXPECT_EQ(mirrored.vertex_subset, (Subsets{1, 1, 0, 0, 0, 1, 1, 1, 0, 0}));
}

TEST(GreedyPartition, OvershootingFrontTakesMinimalUpdatedDegreeFirst) {
  // p = 3 on the strip: targets 4, 3, 3. Subset 0 from 5: {5}, {0, 6} (3 vertices), then the
  // front {1, 7} has room for one: after marking 0, 5, 6 the updated degrees are 1: {2} -> 1,
  // 7: {2, 8} -> 2, so 1 is taken.
  const Mesh mesh = strip();
  const Partition partition = partition_mesh(mesh, 3, options("greedy"));
  expect_valid(mesh, partition, 3);
  EXPECT_EQ(partition.vertex_subset[1], 0u);
  EXPECT_EQ(partition.vertex_subset[7], 1u);  // subset 1 starts next to subset 0
}

TEST(GreedyPartition, LockedInSubsetContinuesInTheNextComponent) {
  // Targets 4, 3: subset 0 fills the triangle {0, 1, 2} (start 1: degree 2, seed 1), is locked
  // in and continues at the unmarked vertex of minimal degree, 3. The isolated vertex comes
  // last and ends in the last subset.
  const Mesh mesh = two_triangles(true);
  const Partition partition = partition_mesh(mesh, 2, options("greedy"));
  expect_valid(mesh, partition, 2);
  EXPECT_EQ(partition.vertex_subset, (Subsets{0, 0, 0, 0, 1, 1, 1}));
  EXPECT_EQ(partition.face_subset, (Subsets{0, 1}));
  const PartitionMetrics metrics = partition_metrics(mesh, partition);
  EXPECT_EQ(metrics.components, (Subsets{2, 2}));  // {0,1,2} + {3}; {4,5} + {6}
  EXPECT_EQ(metrics.cut_edges, 2u);
  EXPECT_EQ(metrics.cut_faces, 1u);
}

TEST(GreedyPartition, DisconnectedTrianglesOnePerSubset) {
  const Mesh mesh = two_triangles(false);
  for (const char* algorithm : {"greedy", "bfs"}) {
    const Partition partition = partition_mesh(mesh, 2, options(algorithm));
    expect_valid(mesh, partition, 2);
    EXPECT_EQ(partition.vertex_subset, (Subsets{0, 0, 0, 1, 1, 1})) << algorithm;
    EXPECT_EQ(partition_metrics(mesh, partition).cut_edges, 0u) << algorithm;
  }
}

TEST(GreedyPartition, IsolatedVerticesOnlyStillGetAssigned) {
  const Mesh mesh = make_mesh(5, {});
  for (const char* algorithm : {"greedy", "bfs"}) {
    const Partition partition = partition_mesh(mesh, 2, options(algorithm));
    expect_valid(mesh, partition, 2);
  }
}

// Balanced by faces, the greedy algorithm counts a face once its owner is settled (two corners
// in one subset, or its third corner): the strip's halves own 4 faces each.
TEST(GreedyPartition, ByFacesTheStripsHalvesOwnFourFacesEach) {
  const Mesh mesh = strip();
  PartitionOptions by_faces = options("greedy");
  by_faces.balance = Balance::kFaces;
  const Partition partition = partition_mesh(mesh, 2, by_faces);
  expect_valid(mesh, partition, 2, {}, Balance::kFaces);
  const PartitionMetrics metrics = partition_metrics(mesh, partition, by_faces);
  EXPECT_EQ(metrics.subset_faces, (std::vector<uint64_t>{4, 4}));
}

// Shares of a few faces, less than one vertex can settle (a grid of 25 vertices and 32 faces
// in 10 subsets by faces): every subset still gets a vertex; without that rule one of the 10
// got none. (With about half as many vertices as subsets or fewer, the greedy subsets, which
// take vertices until their faces are settled, can leave the last ones none: faces cannot be
// spread that thin; 13 subsets of the 6 x 6 grid leave one empty.)
TEST(GreedyPartition, ByFacesEverySubsetGetsAVertexWhenSharesAreTiny) {
  const Mesh mesh = grid(5);
  PartitionOptions by_faces = options("greedy");
  by_faces.balance = Balance::kFaces;
  for (uint32_t p : {8u, 10u}) {
    const Partition partition = partition_mesh(mesh, p, by_faces);
    expect_valid(mesh, partition, p, {}, Balance::kFaces);
    std::vector<uint32_t> vertices(p, 0);
    for (uint32_t s : partition.vertex_subset) ++vertices[s];
    for (uint32_t k = 0; k < p; ++k) EXPECT_GE(vertices[k], 1u) << "p = " << p << ", subset " << k;
  }
}

// The greedy partitioner starts at the seed's pick among the vertices of least degree; where
// fewer than 16 have it, the next degrees join them. A UV sphere's two poles alone have the
// least degree (4): with them only, every seed drew one of two partitions, and the parallel
// build's round 1, drawn on round 0's mesh with another seed, could draw round 0's again.
TEST(GreedyPartition, FewVerticesOfLeastDegreeStillLetSeedsStartElsewhere) {
  const Mesh sphere = testing::uv_sphere(12, 4);
  std::vector<Subsets> drawn;
  for (uint64_t seed = 1; seed <= 8; ++seed) {
    PartitionOptions by_faces;
    by_faces.seed = seed;
    const Subsets subsets = partition_mesh(sphere, 4, by_faces).vertex_subset;
    if (std::find(drawn.begin(), drawn.end(), subsets) == drawn.end()) drawn.push_back(subsets);
  }
  EXPECT_GE(drawn.size(), 4u);
}

TEST(PartitionMesh, GridQuartersAreConnectedAndDeterministic) {
  const Mesh mesh = grid(8);  // 64 vertices, 98 faces
  for (const char* algorithm : {"greedy", "bfs"}) {
    for (uint64_t seed : {0, 1, 7}) {
      const PartitionOptions opts = options(algorithm, seed);
      const Partition partition = partition_mesh(mesh, 4, opts);
      expect_valid(mesh, partition, 4);
      const Partition again = partition_mesh(mesh, 4, opts);
      EXPECT_EQ(partition.vertex_subset, again.vertex_subset);
      EXPECT_EQ(partition.face_subset, again.face_subset);
      const PartitionMetrics metrics = partition_metrics(mesh, partition, opts);
      EXPECT_EQ(metrics.components, (Subsets{1, 1, 1, 1})) << algorithm << " seed " << seed;
      EXPECT_LE(metrics.biggest_faces, 30u) << algorithm;  // ideal 24.5
    }
  }
}

TEST(PartitionMesh, WeightedGrid) {
  const Mesh mesh = grid(10);  // 100 vertices
  for (const char* algorithm : {"greedy", "bfs"}) {
    const PartitionOptions opts = options(algorithm, 1, {1, 2, 3, 4});
    const Partition partition = partition_mesh(mesh, 4, opts);
    expect_valid(mesh, partition, 4, opts.weights);  // 10, 20, 30, 40 vertices
  }
}

// A hub of thousands of faces (a disk's centre) lists each rim vertex once, in the order of
// their first corners, in one pass and in chunks alike; each rim vertex has the hub and its
// two rim neighbours.
TEST(VertexGraph, AHubListsEachNeighbourOnceInTheOrderOfTheirFirstCorners) {
  constexpr uint32_t kRim = 5000;
  Mesh disk;
  disk.positions.resize(kRim + 1);
  for (uint32_t i = 0; i < kRim; ++i) disk.faces.push_back({0, 1 + i, 1 + (i + 1) % kRim});
  ChunkedLoops one_pass;
  ChunkedLoops chunked(4, 2, 16);
  for (ChunkedLoops* loops : {&one_pass, &chunked}) {
    const partition_detail::VertexGraph graph =
        partition_detail::build_vertex_graph(disk, *loops, true);
    ASSERT_EQ(graph.degree(0), kRim);
    for (uint32_t i = 0; i < kRim; ++i) EXPECT_EQ(graph.neighbours_of(0)[i], 1 + i);
    for (uint32_t v = 1; v <= kRim; ++v) EXPECT_EQ(graph.degree(v), 3u) << v;
    EXPECT_EQ(graph.faces_of(0).size(), size_t(kRim));
  }
}

TEST(PartitionMetrics, RejectsAPartitionOfAnotherMesh) {
  const Partition partition = partition_mesh(strip(), 2, {});
  EXPECT_THROW(partition_metrics(grid(3), partition), Error);
}

}  // namespace
}  // namespace parapm
