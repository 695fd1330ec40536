// partition_mesh() on real meshes: the small ones committed under tests/data (every vertex
// assigned, exact vertex targets, faces balanced, weights respected, deterministic), and the
// issue's balance target on every mesh of ../shared/meshes with at least 10k faces (after
// repair): the biggest subset B <= 1.05 x its ideal face count for the greedy algorithm with
// p in {2, 4, ..., 64}. One line per mesh and p is printed: B / ideal, cut edges, the
// components per subset (max and total) and the time.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "partition/partition.h"
#include "partition/partition_metrics.h"
#include "partition_expectations.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

PartitionOptions options(const char* algorithm, std::vector<double> weights = {},
                         uint64_t seed = 1) {
  PartitionOptions result;
  result.algorithm = algorithm;
  result.weights = std::move(weights);
  result.seed = seed;
  return result;
}

Mesh read_repaired(const std::string& path) { return repair_mesh(read_mesh(path)).mesh; }

struct Timed {
  Partition partition;
  double seconds;
};
Timed timed_partition(const Mesh& mesh, uint32_t p, const PartitionOptions& opts) {
  const auto start = std::chrono::steady_clock::now();
  Partition partition = partition_mesh(mesh, p, opts);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return {std::move(partition), seconds};
}

void print_line(const std::string& name, const PartitionMetrics& m) {
  const uint32_t max_components = *std::max_element(m.components.begin(), m.components.end());
  const uint32_t total_components = std::accumulate(m.components.begin(), m.components.end(), 0u);
  std::printf(
      "%-34s %-6s p=%-3u B/ideal=%.4f cut_edges=%-7llu components max=%u total=%u %.1f ms\n",
      name.c_str(), m.algorithm.c_str(), m.p, m.biggest_faces / m.ideal_faces,
      (unsigned long long)m.cut_edges, max_components, total_components, m.seconds * 1000);
}

const char* const kCommitted[] = {"pymeshlab-bunny-textured-10k.obj", "stratocaster-9k.ply",
                                  "cad-cycloidal-43k.ply"};

TEST(PartitionRealMeshes, CompleteBalancedDeterministic) {
  for (const char* name : kCommitted) {
    SCOPED_TRACE(name);
    const Mesh mesh = read_repaired(testing::test_data(name));
    for (const char* algorithm : {"greedy", "bfs"}) {
      for (uint32_t p : {2u, 8u, 32u}) {
        SCOPED_TRACE(std::string(algorithm) + " p=" + std::to_string(p));
        const PartitionOptions opts = options(algorithm);
        const Timed run = timed_partition(mesh, p, opts);
        expect_valid(mesh, run.partition, p, opts.weights, Balance::kFaces,
                     opts.algorithm == "bfs");
        const PartitionMetrics metrics = partition_metrics(mesh, run.partition, opts, run.seconds);
        print_line(name, metrics);
        // Exact vertex targets keep the faces close to balanced on meshes of this size; the
        // 1.05 target of the issue is checked on the shared meshes of >= 10k faces below.
        EXPECT_LE(metrics.biggest_faces, 1.15 * metrics.ideal_faces);
        const Partition again = partition_mesh(mesh, p, opts);
        EXPECT_EQ(run.partition.vertex_subset, again.vertex_subset);
        EXPECT_EQ(run.partition.face_subset, again.face_subset);
        // Its graph built in chunks side by side, by faces and by vertices: the same.
        ChunkedLoops loops(7, 3, 64);
        for (Balance balance : {Balance::kFaces, Balance::kVertices}) {
          PartitionOptions one_pass = opts, chunked = opts;
          one_pass.balance = chunked.balance = balance;
          chunked.loops = &loops;
          const Partition a = partition_mesh(mesh, p, one_pass),
                          b = partition_mesh(mesh, p, chunked);
          EXPECT_EQ(a.vertex_subset, b.vertex_subset);
          EXPECT_EQ(a.face_subset, b.face_subset);
        }
      }
    }
  }
}

TEST(PartitionRealMeshes, WeightsAreRespected) {
  const std::vector<double> weights = {1, 2, 3, 4};
  for (const char* name : kCommitted) {
    SCOPED_TRACE(name);
    const Mesh mesh = read_repaired(testing::test_data(name));
    for (const char* algorithm : {"greedy", "bfs"}) {
      SCOPED_TRACE(algorithm);
      const PartitionOptions opts = options(algorithm, weights);
      const Partition partition = partition_mesh(mesh, 4, opts);
      expect_valid(mesh, partition, 4, weights, Balance::kFaces, opts.algorithm == "bfs");
      const PartitionMetrics metrics = partition_metrics(mesh, partition, opts);
      // Faces within 2% of each subset's ideal (2026-11-25: within 0.31% greedy, 0.79% BFS;
      // when the greedy algorithm counted corners, the worst was cad-cycloidal greedy, subset
      // 1 with 8184 faces for an ideal of 8673.6, -5.6%: its non-manifold pieces have few
      // faces per vertex).
      for (uint32_t k = 0; k < 4; ++k) {
        const double ideal = mesh.face_count() * weights[k] / 10.0;
        EXPECT_NEAR(double(metrics.subset_faces[k]), ideal, 0.02 * ideal) << "subset " << k;
      }
    }
  }
}

TEST(PartitionRealMeshes, OtherSeedsAreValidToo) {
  const Mesh mesh = read_repaired(testing::test_data("stratocaster-9k.ply"));  // 94 components
  for (const char* algorithm : {"greedy", "bfs"}) {
    for (uint64_t seed : {0u, 2u, 12345u}) {
      const Partition partition = partition_mesh(mesh, 16, options(algorithm, {}, seed));
      expect_valid(mesh, partition, 16, {}, Balance::kFaces, std::string(algorithm) == "bfs");
    }
  }
}

// One graph, several partitions (other seeds, p, algorithms, refined), two of them drawn on two
// threads at once: each what partition_mesh draws from scratch. A graph built for one balance
// refuses to draw by the other.
TEST(PartitionGraph, DrawsWhatPartitionMeshDraws) {
  const Mesh mesh = read_repaired(testing::test_data("stratocaster-9k.ply"));  // 94 components
  for (Balance balance : {Balance::kFaces, Balance::kVertices}) {
    const PartitionGraph graph(mesh, balance);
    for (const char* algorithm : {"greedy", "bfs"})
      for (uint32_t p : {2u, 16u})
        for (uint64_t seed : {1u, 7u})
          for (bool refine : {false, true}) {
            PartitionOptions opts = options(algorithm, {}, seed);
            opts.balance = balance;
            opts.refine = refine;
            const Partition drawn = graph.draw(p, opts), fresh = partition_mesh(mesh, p, opts);
            EXPECT_EQ(drawn.vertex_subset, fresh.vertex_subset)
                << algorithm << " p=" << p << " seed " << seed << " refine " << refine;
            EXPECT_EQ(drawn.face_subset, fresh.face_subset);
          }
    PartitionOptions a = options("greedy", {}, 3), b = options("greedy", {}, 4);
    a.balance = b.balance = balance;
    Partition beside;
    std::thread other([&] { beside = graph.draw(8, b); });
    const Partition here = graph.draw(8, a);
    other.join();
    EXPECT_EQ(here.vertex_subset, partition_mesh(mesh, 8, a).vertex_subset);
    EXPECT_EQ(beside.vertex_subset, partition_mesh(mesh, 8, b).vertex_subset);
    PartitionOptions other_balance = a;
    other_balance.balance = balance == Balance::kFaces ? Balance::kVertices : Balance::kFaces;
    EXPECT_THROW(graph.draw(8, other_balance), Error);
  }
}

// Shares count faces (Balance::kFaces, the default): with vertex counts this target was
// missed on the meshes the repair step cuts into many small pieces (openfoam-motorbike-332k
// up to 3.01, stanford-dragon-res3/res4 up to 1.17/1.30, cad-cycloidal-43k 1.057), because
// equal vertex counts are not equal face counts there.
// Refinement never makes things worse: fewer or as many cut edges and components, the same
// balance bound, deterministic.
void expect_refinement_helps(const std::string& name, const Mesh& mesh, uint32_t p) {
  PartitionOptions plain = options("greedy");
  PartitionOptions refined = plain;
  refined.refine = true;
  const Partition a = partition_mesh(mesh, p, plain);
  const Partition b = partition_mesh(mesh, p, refined);
  EXPECT_EQ(b.vertex_subset, partition_mesh(mesh, p, refined).vertex_subset);
  const PartitionMetrics ma = partition_metrics(mesh, a, plain);
  const PartitionMetrics mb = partition_metrics(mesh, b, refined);
  ASSERT_EQ(b.vertex_subset.size(), mesh.vertex_count());
  for (uint32_t s : b.vertex_subset) ASSERT_LT(s, p);
  EXPECT_LE(mb.cut_edges, ma.cut_edges) << name << " p=" << p;
  EXPECT_LE(double(mb.biggest_faces), std::max(1.05 * mb.ideal_faces, double(ma.biggest_faces)))
      << name << " p=" << p;
  const auto total = [](const std::vector<uint32_t>& c) {
    return std::accumulate(c.begin(), c.end(), uint64_t(0));
  };
  EXPECT_LE(total(mb.components), total(ma.components)) << name << " p=" << p;
  std::printf(
      "%-34s refine p=%-3u cut_edges %6llu -> %6llu  components %6llu -> %6llu  B/ideal %.4f\n",
      name.c_str(), p, (unsigned long long)ma.cut_edges, (unsigned long long)mb.cut_edges,
      (unsigned long long)total(ma.components), (unsigned long long)total(mb.components),
      double(mb.biggest_faces) / mb.ideal_faces);
}

TEST(PartitionRealMeshes, RefinementCutsFewerEdgesWithinTheBound) {
  for (const char* name : kCommitted) {
    const Mesh mesh = read_repaired(testing::test_data(name));
    for (uint32_t p : {2u, 8u, 32u}) expect_refinement_helps(name, mesh, p);
  }
}

TEST(PartitionSharedMeshes, GreedyBiggestSubsetWithinFivePercent) {
  const auto files = testing::shared_meshes();
  if (files.empty()) GTEST_SKIP() << "no shared meshes folder at " << testing::shared_meshes_dir();
  for (const auto& file : files) {
    const std::string name = file.filename().string();
    SCOPED_TRACE(name);
    const Mesh mesh = read_repaired(file.string());
    if (mesh.face_count() < 10000) continue;
    for (uint32_t p : {2u, 4u, 8u, 16u, 32u, 64u}) {
      const PartitionOptions opts = options("greedy");
      const Timed run = timed_partition(mesh, p, opts);
      expect_valid(mesh, run.partition, p, {}, Balance::kFaces);
      const PartitionMetrics metrics = partition_metrics(mesh, run.partition, opts, run.seconds);
      print_line(name, metrics);
      EXPECT_LE(metrics.biggest_faces, 1.05 * metrics.ideal_faces) << "p=" << p;
      if (p == 4 || p == 16) expect_refinement_helps(name, mesh, p);
    }
  }
}

}  // namespace
}  // namespace parapm
