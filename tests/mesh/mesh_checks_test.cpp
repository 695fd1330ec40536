// The invariant checker and topology statistics on tiny meshes with known answers.
#include "mesh/mesh_checks.h"

#include <gtest/gtest.h>

#include <string>

#include "util/error.h"

namespace parapm {
namespace {

Mesh make_mesh(size_t vertices, std::vector<Triangle> faces) {
  Mesh mesh;
  mesh.positions.resize(vertices, Vec3{0, 0, 0});
  for (size_t v = 0; v < vertices; ++v) mesh.positions[v] = {double(v), double(v * v), 0};
  mesh.faces = std::move(faces);
  return mesh;
}

// A closed tetrahedron, consistently oriented.
const std::vector<Triangle> kTetrahedron{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};

TEST(TopologyStats, ClosedTetrahedron) {
  const TopologyStats stats = topology_stats(make_mesh(4, kTetrahedron));
  EXPECT_EQ(stats.edges, 6u);
  EXPECT_EQ(stats.boundary_edges, 0u);
  EXPECT_EQ(stats.nonmanifold_edges, 0u);
  EXPECT_EQ(stats.nonmanifold_vertices, 0u);
  EXPECT_EQ(stats.components, 1u);
  EXPECT_EQ(stats.euler_characteristic, 2);
  EXPECT_TRUE(is_oriented_manifold(make_mesh(4, kTetrahedron)));
}

TEST(TopologyStats, SquareWithIsolatedVertexAndDegenerateFace) {
  //   3 --- 2
  //   |   / |      4 (isolated)
  //   | /   |
  //   0 --- 1      plus (1, 1, 2), degenerate
  const Mesh mesh = make_mesh(5, {{0, 1, 2}, {0, 2, 3}, {1, 1, 2}});
  const TopologyStats stats = topology_stats(mesh);
  EXPECT_EQ(stats.vertices, 5u);
  EXPECT_EQ(stats.isolated_vertices, 1u);
  EXPECT_EQ(stats.degenerate_faces, 1u);
  EXPECT_EQ(stats.edges, 5u);
  EXPECT_EQ(stats.boundary_edges, 4u);
  EXPECT_EQ(stats.components, 1u);
  EXPECT_EQ(stats.euler_characteristic, 1);
  std::string why;
  EXPECT_FALSE(is_oriented_manifold(mesh, &why));
  EXPECT_EQ(why, "face 2 is degenerate (1, 1, 2)");
  EXPECT_TRUE(is_oriented_manifold(make_mesh(5, {{0, 1, 2}, {0, 2, 3}}), &why)) << why;
}

TEST(IsOrientedManifold, BookOfThreePagesIsNot) {
  const Mesh mesh = make_mesh(5, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  std::string why;
  EXPECT_FALSE(is_oriented_manifold(mesh, &why));
  EXPECT_EQ(why, "edge (0, 1) has 3 faces: 0, 1, 2");
  const TopologyStats stats = topology_stats(mesh);
  EXPECT_EQ(stats.nonmanifold_edges, 1u);
  EXPECT_EQ(stats.inconsistent_edges, 0u);
  EXPECT_EQ(stats.nonmanifold_vertices, 2u);
}

TEST(IsOrientedManifold, SameDirectionEdgeIsNot) {
  const Mesh mesh = make_mesh(4, {{0, 1, 2}, {0, 1, 3}});
  std::string why;
  EXPECT_FALSE(is_oriented_manifold(mesh, &why));
  EXPECT_EQ(why, "edge (0, 1) is used in the same direction by faces 0 and 1");
  EXPECT_EQ(topology_stats(mesh).inconsistent_edges, 1u);
}

TEST(IsOrientedManifold, BowtieIsNot) {
  const Mesh mesh = make_mesh(5, {{0, 1, 2}, {2, 4, 3}});
  std::string why;
  EXPECT_FALSE(is_oriented_manifold(mesh, &why));
  EXPECT_EQ(why, "vertex 2 has 2 separate fans of faces (holding faces 0, 1)");
  EXPECT_EQ(topology_stats(mesh).components, 1u);  // joined through the vertex
}

TEST(IsOrientedManifold, OutOfRangeCorner) {
  const Mesh mesh = make_mesh(3, {{0, 1, 3}});
  std::string why;
  EXPECT_FALSE(is_oriented_manifold(mesh, &why));
  EXPECT_EQ(why, "face 0 corner 2 refers to vertex 3, but the mesh has 3 vertices");
  EXPECT_THROW(topology_stats(mesh), Error);
}

TEST(IsOrientedManifold, OppositeFacesMakeAClosedPillow) {
  EXPECT_TRUE(is_oriented_manifold(make_mesh(3, {{0, 1, 2}, {0, 2, 1}})));
}

TEST(WedgesAreConsistent, CatchesAWedgeOfAnotherVertex) {
  Mesh mesh = make_mesh(3, {{0, 1, 2}});
  mesh.layout.texcoords = true;
  mesh.wedge_vertex = {0, 1, 2};
  mesh.wedge_values = {0, 0, 1, 0, 0, 1};
  mesh.face_wedges = {{0, 1, 2}};
  std::string why;
  EXPECT_TRUE(wedges_are_consistent(mesh, &why)) << why;
  mesh.face_wedges = {{0, 2, 1}};
  EXPECT_FALSE(wedges_are_consistent(mesh, &why));
  EXPECT_EQ(why, "face 0 corner 1 uses wedge 2 of vertex 2, but the corner's vertex is 1");
}

}  // namespace
}  // namespace parapm
