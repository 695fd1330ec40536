// Rule 5 of the repair (spatial_order.h): vertices along a Morton curve, faces by their first
// vertex, wedges by their vertex; the maps back to the input follow.
#include "mesh/spatial_order.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "repair_expectations.h"
#include "test_support.h"

namespace parapm {
namespace {

using testing::expect_faithful_repair;
using testing::RepairOrder;

// `mesh` with its vertices, wedges and faces numbered at random (the same surface).
Mesh shuffled(const Mesh& mesh, uint32_t seed) {
  std::mt19937 random(seed);
  std::vector<VertexId> new_vertex(mesh.vertex_count());
  std::iota(new_vertex.begin(), new_vertex.end(), 0);
  std::shuffle(new_vertex.begin(), new_vertex.end(), random);
  std::vector<FaceId> face_order(mesh.face_count());
  std::iota(face_order.begin(), face_order.end(), 0);
  std::shuffle(face_order.begin(), face_order.end(), random);
  std::vector<WedgeId> new_wedge(mesh.wedge_count());
  std::iota(new_wedge.begin(), new_wedge.end(), 0);
  std::shuffle(new_wedge.begin(), new_wedge.end(), random);

  Mesh out;
  out.layout = mesh.layout;
  out.positions_are_float = mesh.positions_are_float;
  out.positions.resize(mesh.vertex_count());
  for (VertexId v = 0; v < mesh.vertex_count(); ++v)
    out.positions[new_vertex[v]] = mesh.positions[v];
  for (FaceId f : face_order) {
    const Triangle& t = mesh.faces[f];
    out.faces.push_back({new_vertex[t[0]], new_vertex[t[1]], new_vertex[t[2]]});
    if (mesh.layout.any()) {
      const auto& w = mesh.face_wedges[f];
      out.face_wedges.push_back({new_wedge[w[0]], new_wedge[w[1]], new_wedge[w[2]]});
    }
  }
  if (mesh.layout.any()) {
    const size_t floats = size_t(mesh.layout.floats_per_wedge());
    out.wedge_vertex.resize(mesh.wedge_count());
    out.wedge_values.resize(mesh.wedge_values.size());
    for (WedgeId w = 0; w < mesh.wedge_count(); ++w) {
      out.wedge_vertex[new_wedge[w]] = new_vertex[mesh.wedge_vertex[w]];
      std::copy_n(mesh.wedge(w), floats,
                  out.wedge_values.begin() + ptrdiff_t(new_wedge[w] * floats));
    }
  }
  return out;
}

// The median, over the faces' edges, of how far apart their two ends are numbered: what a
// collapse's reads of its star spread over.
uint64_t median_edge_span(const Mesh& mesh) {
  std::vector<uint64_t> spans;
  for (const Triangle& t : mesh.faces)
    for (int k = 0; k < 3; ++k)
      spans.push_back(uint64_t(std::max(t[k], t[(k + 1) % 3]) - std::min(t[k], t[(k + 1) % 3])));
  std::nth_element(spans.begin(), spans.begin() + ptrdiff_t(spans.size() / 2), spans.end());
  return spans[spans.size() / 2];
}

void expect_spatially_ordered(const Mesh& mesh) {
  const Box box = bounding_box(mesh);
  for (VertexId v = 1; v < mesh.vertex_count(); ++v)
    ASSERT_LE(morton_code(mesh.positions[v - 1], box), morton_code(mesh.positions[v], box))
        << "vertex " << v;
  auto first = [](const Triangle& t) { return std::min({t[0], t[1], t[2]}); };
  for (FaceId f = 1; f < mesh.face_count(); ++f)
    ASSERT_LE(first(mesh.faces[f - 1]), first(mesh.faces[f])) << "face " << f;
  for (WedgeId w = 1; w < mesh.wedge_count(); ++w)
    ASSERT_LE(mesh.wedge_vertex[w - 1], mesh.wedge_vertex[w]) << "wedge " << w;
}

TEST(SpatialOrder, MortonCodeInterleavesTheAxes) {
  Box box;
  box.max = {1, 1, 1};
  const double step = 1.0 / double((1u << 21) - 1);
  EXPECT_EQ(morton_code({0, 0, 0}, box), 0u);
  EXPECT_EQ(morton_code({step, 0, 0}, box), 1u);  // x is the lowest bit, then y, then z
  EXPECT_EQ(morton_code({0, step, 0}, box), 2u);
  EXPECT_EQ(morton_code({0, 0, step}, box), 4u);
  EXPECT_EQ(morton_code({2 * step, 0, 0}, box), 8u);
  EXPECT_EQ(morton_code({1, 1, 1}, box), (uint64_t(1) << 63) - 1);
  EXPECT_EQ(morton_code({5, -5, 1}, box), morton_code({1, 0, 1}, box));  // clamped
  Box flat = box;
  flat.max[2] = 0;  // no extent along z
  EXPECT_EQ(morton_code({0, 0, 0.5}, flat), 0u);
}

// A textured real mesh with seams (several wedges per vertex), numbered at random: the repair
// orders it, keeps every map back to the input, and ordering again changes nothing.
TEST(SpatialOrder, ShuffledRealMeshComesOutInOrderAndFaithful) {
  const Mesh input = shuffled(read_mesh(testing::test_data("pymeshlab-bunny-textured-10k.obj")), 7);
  ASSERT_TRUE(input.layout.any());
  const RepairedMesh ordered = repair_mesh(input);
  expect_faithful_repair(input, ordered, RepairOrder::kAny);
  expect_spatially_ordered(ordered.mesh);

  RepairOptions unordered_options;
  unordered_options.spatial_order = false;
  RepairedMesh unordered = repair_mesh(input, unordered_options);
  expect_faithful_repair(input, unordered, RepairOrder::kInput);
  std::printf("median edge span: %llu in the shuffled input, %llu ordered (%zu vertices)\n",
              (unsigned long long)median_edge_span(unordered.mesh),
              (unsigned long long)median_edge_span(ordered.mesh), ordered.mesh.vertex_count());
  EXPECT_GT(median_edge_span(unordered.mesh), ordered.mesh.vertex_count() / 8);
  EXPECT_LT(median_edge_span(ordered.mesh), ordered.mesh.vertex_count() / 100);

  // The repair's last step is order_spatially on rules 1-4's output.
  order_spatially(unordered);
  testing::expect_same_repair(unordered, ordered);

  // Idempotent: an ordered mesh is its own order.
  RepairedMesh again = ordered;
  order_spatially(again);
  testing::expect_same_repair(again, ordered);

  // In chunks side by side (a sample sort of the codes, counting sorts per range): the same.
  for (unsigned chunks : {2u, 7u}) {
    ChunkedLoops loops(chunks, 2, 64);
    RepairOptions in_chunks;
    in_chunks.loops = &loops;
    testing::expect_same_repair(repair_mesh(input, in_chunks), ordered);
  }
}

// Per-vertex attributes (a PLY's colours: wedge i of vertex i) stay per vertex.
TEST(SpatialOrder, PerVertexWedgesStayPerVertex) {
  const Mesh input =
      shuffled(read_mesh(testing::test_data("pymeshlab-colored-airplane-11k.ply")), 3);
  ASSERT_TRUE(input.layout.colors);
  const RepairedMesh ordered = repair_mesh(input);
  expect_faithful_repair(input, ordered, RepairOrder::kAny);
  expect_spatially_ordered(ordered.mesh);
  ASSERT_EQ(ordered.mesh.wedge_count(), ordered.mesh.vertex_count());
  for (WedgeId w = 0; w < ordered.mesh.wedge_count(); ++w)
    ASSERT_EQ(ordered.mesh.wedge_vertex[w], w);
}

// Coordinates at the ends of the double range: the codes' arithmetic overflows (infinite
// extents, NaN ratios), which must only clamp.
TEST(SpatialOrder, CoordinatesNearTheDoubleRangeClamp) {
  Mesh mesh;
  const double big = 1e308;
  mesh.positions = {{-big, -big, 0}, {big, -big, 0}, {big, big, 1}, {-big, big, -1}, {0, 0, 0}};
  mesh.faces = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  const RepairedMesh ordered = repair_mesh(mesh);
  expect_faithful_repair(mesh, ordered, RepairOrder::kAny);
  expect_spatially_ordered(ordered.mesh);
}

TEST(SpatialOrder, EmptyAndSingleFaceMeshes) {
  EXPECT_EQ(repair_mesh(Mesh{}).mesh.vertex_count(), 0u);
  Mesh one;
  one.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}};
  one.faces = {{2, 1, 0}};
  RepairOptions keep;
  keep.keep_unreferenced = true;
  const RepairedMesh ordered = repair_mesh(one, keep);
  expect_faithful_repair(one, ordered, RepairOrder::kAny);
  expect_spatially_ordered(ordered.mesh);
  // Codes: (0,0,0) 0, then (1,0,0) (x bits), (0,1,0) (y bits, one higher), (5,5,5) (all).
  EXPECT_EQ(ordered.mesh.faces, (std::vector<Triangle>{{2, 1, 0}}));
}

}  // namespace
}  // namespace parapm
