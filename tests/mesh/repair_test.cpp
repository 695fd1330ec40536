// repair_mesh() on tiny meshes drawn in code: one case per rule of repair.h, with exact counts.
// Rules 1-4 are checked in the input's order (rule 5 off: their exact outputs are readable);
// rule 5 has its own tests (spatial_order_test.cpp).
#include "mesh/repair.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "drawn_meshes.h"
#include "mesh/mesh_checks.h"
#include "repair_expectations.h"
#include "util/error.h"

namespace parapm {
namespace {

using testing::expect_faithful_repair;

// repair_mesh() with rules 1-4 only: the output in the input's order.
RepairedMesh repair_in_input_order(const Mesh& mesh, RepairOptions options = {}) {
  options.spatial_order = false;
  return repair_mesh(mesh, options);
}

Mesh make_mesh(std::vector<Vec3> positions, std::vector<Triangle> faces) {
  Mesh mesh;
  mesh.positions = std::move(positions);
  mesh.faces = std::move(faces);
  return mesh;
}

// Per-vertex texture coordinates (u = x, v = y), one wedge per vertex as a PLY reader makes.
void add_vertex_texcoords(Mesh* mesh) {
  mesh->layout.texcoords = true;
  for (size_t v = 0; v < mesh->vertex_count(); ++v) {
    mesh->wedge_vertex.push_back(VertexId(v));
    mesh->wedge_values.push_back(float(mesh->positions[v][0]));
    mesh->wedge_values.push_back(float(mesh->positions[v][1]));
  }
  for (const Triangle& t : mesh->faces) mesh->face_wedges.push_back({t[0], t[1], t[2]});
}

// Runs repair_mesh and returns the message of the Error(kInvalidInput) it must throw.
std::string repair_error(const Mesh& mesh) {
  try {
    repair_in_input_order(mesh);
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kInvalidInput) << error.what();
    return error.what();
  }
  ADD_FAILURE() << "repair_mesh accepted the mesh";
  return {};
}

// A unit square in the plane z = 0, two faces:
//   3 --- 2
//   |   / |
//   |  /  |
//   | /   |
//   0 --- 1
Mesh square() {
  return make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 3}});
}

// Two triangles that touch at vertex 2 only:
//   0       3
//   | \   / |
//   |   2   |
//   | /   \ |
//   1       4
Mesh bowtie() {
  return make_mesh({{0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {2, 1, 0}, {2, -1, 0}},
                   {{0, 1, 2}, {2, 4, 3}});
}

// A closed tetrahedron on vertices 0..3, outward-facing.
std::vector<Triangle> tetrahedron(VertexId a, VertexId b, VertexId c, VertexId d) {
  return {{a, c, b}, {a, b, d}, {b, c, d}, {c, a, d}};
}
std::vector<Vec3> tetrahedron_positions(double x) {
  return {{x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}, {x, 0, 1}};
}

// ---------------------------------------------------------------------------------------
// Step 1: errors.

TEST(RepairErrors, NanCoordinateNamesTheVertex) {
  Mesh mesh = square();
  mesh.positions[2][0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(repair_error(mesh), "vertex 2 has a non-finite coordinate (nan, 1, 0)");
}

TEST(RepairErrors, InfiniteCoordinateOfUnreferencedVertex) {
  Mesh mesh = square();
  mesh.positions.push_back({0, -std::numeric_limits<double>::infinity(), 0});
  EXPECT_EQ(repair_error(mesh), "vertex 4 has a non-finite coordinate (0, -inf, 0)");
}

TEST(RepairErrors, NanAttributeNamesTheWedgeAndChannel) {
  Mesh mesh = square();
  add_vertex_texcoords(&mesh);
  mesh.wedge_values[2 * 3 + 1] = std::nanf("");
  EXPECT_EQ(repair_error(mesh), "wedge 3 (vertex 3) has a non-finite texcoord (0, nan)");
}

TEST(RepairErrors, InfiniteColorIsAnError) {
  Mesh mesh = square();
  mesh.layout.colors = true;
  for (VertexId v = 0; v < 4; ++v) {
    mesh.wedge_vertex.push_back(v);
    mesh.wedge_values.insert(mesh.wedge_values.end(), {1, 1, 1, 1});
  }
  mesh.face_wedges = {{0, 1, 2}, {0, 2, 3}};
  mesh.wedge_values[4 * 1 + 3] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(repair_error(mesh), "wedge 1 (vertex 1) has a non-finite color (1, 1, 1, inf)");
}

TEST(RepairErrors, OutOfRangeCornerNamesTheFace) {
  Mesh mesh = square();
  mesh.faces[1][2] = 7;
  EXPECT_EQ(repair_error(mesh), "face 1 corner 2 refers to vertex 7, but the mesh has 4 vertices");
}

TEST(RepairErrors, WedgeOfAnotherVertexIsAnError) {
  Mesh mesh = square();
  add_vertex_texcoords(&mesh);
  mesh.face_wedges[1][1] = 1;  // corner of vertex 2 using vertex 1's wedge
  EXPECT_EQ(repair_error(mesh),
            "face 1 corner 1 (vertex 2) uses wedge 1, which belongs to vertex 1");
}

TEST(RepairErrors, WedgeArraysOfTheWrongSize) {
  Mesh mesh = square();
  add_vertex_texcoords(&mesh);
  Mesh short_values = mesh;
  short_values.wedge_values.pop_back();
  EXPECT_EQ(repair_error(short_values), "wedge_values has 7 floats, expected 4 wedges x 2 floats");
  Mesh missing_face = mesh;
  missing_face.face_wedges.pop_back();
  EXPECT_EQ(repair_error(missing_face), "face_wedges has 1 entries, expected one per face (2)");
  Mesh wedge_out_of_range = mesh;
  wedge_out_of_range.face_wedges[0][0] = 9;
  EXPECT_EQ(repair_error(wedge_out_of_range),
            "face 0 corner 0 uses wedge 9, but the mesh has 4 wedges");
  Mesh wedges_without_layout = mesh;
  wedges_without_layout.layout = {};
  wedges_without_layout.wedge_values.clear();
  EXPECT_EQ(repair_error(wedges_without_layout),
            "mesh has no attribute channels but 4 wedges, 0 wedge values and 2 face wedge triples");
}

// ---------------------------------------------------------------------------------------
// Steps 2 and 3: faces and vertices.

TEST(Repair, CleanMeshIsUnchanged) {
  const Mesh mesh = square();
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_FALSE(repaired.report.changed());
  EXPECT_EQ(repaired.mesh.faces, mesh.faces);
  EXPECT_EQ(repaired.mesh.positions, mesh.positions);
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, DegenerateFacesRemoved) {
  // The square plus (0, 0, 1) and (2, 3, 2): a vertex repeated.
  Mesh mesh = square();
  mesh.faces.insert(mesh.faces.begin() + 1, Triangle{0, 0, 1});
  mesh.faces.push_back({2, 3, 2});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.degenerate_faces_removed, 2u);
  EXPECT_EQ(repaired.mesh.faces, square().faces);
  EXPECT_EQ(repaired.input_face, (std::vector<FaceId>{0, 2}));
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, DuplicateFacesRemovedInAnyRotationKeepingTheFirst) {
  // Face 0 = (0, 1, 2) again as (1, 2, 0) and (2, 0, 1); face 1 = (0, 2, 3) again as is.
  Mesh mesh = square();
  mesh.faces.push_back({1, 2, 0});
  mesh.faces.push_back({0, 2, 3});
  mesh.faces.push_back({2, 0, 1});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.duplicate_faces_removed, 3u);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 0u);
  EXPECT_EQ(repaired.mesh.faces, square().faces);
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, DuplicateWithOtherWedgesStillRemoved) {
  Mesh mesh = square();
  add_vertex_texcoords(&mesh);
  // A second wedge on vertex 1, used by a copy of face 0.
  mesh.wedge_vertex.push_back(1);
  mesh.wedge_values.insert(mesh.wedge_values.end(), {0.5f, 0.5f});
  mesh.faces.push_back({0, 1, 2});
  mesh.face_wedges.push_back({0, 4, 2});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.duplicate_faces_removed, 1u);
  EXPECT_EQ(repaired.mesh.face_wedges[0], (std::array<WedgeId, 3>{0, 1, 2}));
  EXPECT_EQ(repaired.mesh.wedge_count(), 5u);  // the unused wedge of a kept vertex stays
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, OppositeOrientationKept) {
  // (0, 1, 2) and (0, 2, 1): a two-face "pillow", each edge used once in each direction,
  // which is a (flat) closed manifold.
  const Mesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}, {0, 2, 1}});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_FALSE(repaired.report.changed());
  EXPECT_EQ(repaired.report.nonmanifold_edges, 0u);
  EXPECT_EQ(repaired.mesh.faces, mesh.faces);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.boundary_edges, 0u);
  EXPECT_EQ(stats.euler_characteristic, 2);
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, UnreferencedVerticesRemovedAndRenumberedInOrder) {
  // Vertices 0 and 3 are used by no face (3 only by a degenerate one):
  //   x0   1 --- 2
  //        |   /
  //        |  /    x3
  //        | /
  //        4
  Mesh mesh =
      make_mesh({{9, 9, 9}, {0, 1, 0}, {1, 1, 0}, {5, 5, 5}, {0, 0, 0}}, {{1, 4, 2}, {3, 3, 1}});
  add_vertex_texcoords(&mesh);
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.unreferenced_vertices_removed, 2u);
  EXPECT_EQ(repaired.mesh.faces, (std::vector<Triangle>{{0, 2, 1}}));
  EXPECT_EQ(repaired.input_vertex, (std::vector<VertexId>{1, 2, 4}));
  EXPECT_EQ(repaired.input_wedge, (std::vector<WedgeId>{1, 2, 4}));
  EXPECT_EQ(repaired.mesh.wedge_vertex, (std::vector<VertexId>{0, 1, 2}));
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, UnreferencedVerticesKeptWhenAsked) {
  Mesh mesh = square();
  mesh.positions.insert(mesh.positions.begin(), Vec3{7, 7, 7});
  for (Triangle& t : mesh.faces)
    for (VertexId& v : t) ++v;
  add_vertex_texcoords(&mesh);
  RepairOptions options;
  options.keep_unreferenced = true;
  const RepairedMesh repaired = repair_in_input_order(mesh, options);
  EXPECT_EQ(repaired.report.unreferenced_vertices_removed, 0u);
  EXPECT_EQ(repaired.mesh.positions, mesh.positions);
  EXPECT_EQ(repaired.mesh.faces, mesh.faces);
  EXPECT_EQ(repaired.mesh.wedge_count(), 5u);
  EXPECT_EQ(topology_stats(repaired.mesh).isolated_vertices, 1u);
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, ZeroAreaFacesCountedAndKept) {
  // Face 1 has three collinear vertices, face 2 two vertices at the same place (4 on 1).
  //   3 --- 2
  //   |   / |
  //   |  /  |
  //   | /   |
  //   0 -5- 1=4
  Mesh mesh = square();
  mesh.positions.push_back({1, 0, 0});    // 4, on top of 1
  mesh.positions.push_back({0.5, 0, 0});  // 5, between 0 and 1
  mesh.faces.push_back({0, 5, 1});
  mesh.faces.push_back({1, 4, 2});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.zero_area_faces, 2u);
  EXPECT_EQ(repaired.mesh.face_count(), 4u);
  EXPECT_FALSE(repaired.report.changed());
  expect_faithful_repair(mesh, repaired);
}

// ---------------------------------------------------------------------------------------
// Step 4: non-manifold edges and vertices.

TEST(RepairManifold, BowtieVertexSplitIntoTwo) {
  const Mesh mesh = bowtie();
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 0u);
  EXPECT_EQ(repaired.report.nonmanifold_vertices, 1u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 1u);
  // Face 0 (the lowest) keeps vertex 2; face 1 gets the copy, vertex 5.
  EXPECT_EQ(repaired.mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {5, 4, 3}}));
  EXPECT_EQ(repaired.input_vertex, (std::vector<VertexId>{0, 1, 2, 3, 4, 2}));
  EXPECT_EQ(repaired.mesh.positions[5], mesh.positions[2]);
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, TwoClosedFansAtOneVertexSplit) {
  // Two tetrahedra that touch at one vertex (3 of the first is 3 of the second): the vertex
  // has two disks of faces.
  std::vector<Vec3> positions = tetrahedron_positions(0);
  positions.push_back({1, 1, 2});
  positions.push_back({0, 1, 2});
  positions.push_back({0, 0, 2});
  std::vector<Triangle> faces = tetrahedron(0, 1, 2, 3);
  for (const Triangle& t : tetrahedron(4, 5, 6, 3)) faces.push_back(t);
  const Mesh mesh = make_mesh(positions, faces);
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 0u);
  EXPECT_EQ(repaired.report.nonmanifold_vertices, 1u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 1u);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.boundary_edges, 0u);
  EXPECT_EQ(stats.euler_characteristic, 4);  // two spheres
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, BookOfThreePagesCutAlongItsSpine) {
  // Edge 0-1 (the spine) has three faces (pages) ending at 2, 3 and 4:
  //        2   3   4
  //         \  |  /
  //          \ | /
  //   0 ======spine====== 1
  // (0, 1, 2) and (0, 1, 4) use it as 0 -> 1, (1, 0, 3) as 1 -> 0. Every page becomes its
  // own triangle: 0 and 1 get two copies each.
  const Mesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, 0, 1}, {0.5, -1, 0}},
                              {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  EXPECT_EQ(repaired.report.nonmanifold_vertices, 2u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 4u);
  // Copies numbered by original vertex, then by face: 5, 6 for vertex 0; 7, 8 for vertex 1.
  EXPECT_EQ(repaired.mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {7, 5, 3}, {6, 8, 4}}));
  EXPECT_EQ(topology_stats(repaired.mesh).components, 3u);
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, SameDirectionEdgeCut) {
  // The square folded wrong: (0, 1, 2) and (0, 1, 3) both use edge 0 -> 1.
  //   3     2
  //    \   /
  //     0-1     (3 drawn above for clarity; it is below the edge in the plane)
  const Mesh mesh =
      make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, -1, 0}}, {{0, 1, 2}, {0, 1, 3}});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  EXPECT_EQ(repaired.report.nonmanifold_vertices, 2u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 2u);
  EXPECT_EQ(repaired.mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {4, 5, 3}}));
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, WedgesCopiedWithTheSplitVertex) {
  // The bowtie with texture coordinates: vertex 2 has two wedges, 2 for face 0 and 5 for
  // face 1 (a seam), and vertex 0 a wedge no face uses (6).
  Mesh mesh = bowtie();
  add_vertex_texcoords(&mesh);
  mesh.wedge_vertex.push_back(2);  // wedge 5
  mesh.wedge_values.insert(mesh.wedge_values.end(), {0.25f, 0.75f});
  mesh.wedge_vertex.push_back(0);  // wedge 6
  mesh.wedge_values.insert(mesh.wedge_values.end(), {0.5f, 0.5f});
  mesh.face_wedges[1] = {5, 4, 3};
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.vertex_copies_added, 1u);
  // The copy (vertex 5) takes a copy of wedge 5 (wedge 7); wedge 5 stays on vertex 2.
  ASSERT_EQ(repaired.mesh.wedge_count(), 8u);
  EXPECT_EQ(repaired.mesh.face_wedges[1], (std::array<WedgeId, 3>{7, 4, 3}));
  EXPECT_EQ(repaired.mesh.wedge_vertex[7], 5u);
  EXPECT_EQ(repaired.mesh.wedge_vertex[5], 2u);
  EXPECT_EQ(repaired.input_wedge[7], 5u);
  EXPECT_EQ(repaired.mesh.wedge(7)[0], 0.25f);
  EXPECT_EQ(repaired.mesh.wedge(7)[1], 0.75f);
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, SharedWedgeCopiedOncePerFan) {
  // The book of three pages with one wedge per vertex: each copy of 0 and of 1 needs its own
  // wedge, shared by the corners of its fan.
  Mesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, 0, 1}, {0.5, -1, 0}},
                        {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  add_vertex_texcoords(&mesh);
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.mesh.wedge_count(), 5u + 4u);
  EXPECT_EQ(repaired.input_wedge, (std::vector<WedgeId>{0, 1, 2, 3, 4, 0, 0, 1, 1}));
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, CutEdgeStaysAnEdgeWhenItsFacesShareFansAtBothEnds) {
  // The subtle case. A closed tetrahedron on 0..3 plus a fourth face (0, 1, 4) on its edge
  // 0-1, which has three faces and is cut. Around 0, the tetrahedron's three faces are still
  // joined through edges 0-2 and 0-3: one fan (a chain, since 0-1 is cut); the extra face is
  // another fan and takes a copy. The same holds at 1. So the tetrahedron's two faces on 0-1
  // keep both vertices, and 0-1 is again an edge with two opposite faces in the output: the
  // chain closes into a disk and the tetrahedron stays closed. No non-disk vertex can come
  // out of this (see repair.cpp), which the manifold check confirms.
  std::vector<Vec3> positions = tetrahedron_positions(0);
  positions.push_back({0.5, -1, -1});
  std::vector<Triangle> faces = tetrahedron(0, 1, 2, 3);
  faces.push_back({0, 1, 4});
  const Mesh mesh = make_mesh(positions, faces);
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  EXPECT_EQ(repaired.report.nonmanifold_vertices, 2u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 2u);
  EXPECT_EQ(repaired.mesh.faces[4], (Triangle{5, 6, 4}));
  for (int f = 0; f < 4; ++f) EXPECT_EQ(repaired.mesh.faces[f], faces[f]);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.boundary_edges, 3u);  // only the extra triangle's
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.nonmanifold_vertices, 0u);
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, ThirdFaceOnASpokeOpensTheDisk) {
  // A closed fan of six faces around centre 0 (ring 1..6), plus face (0, 1, 7) on spoke 0-1:
  //        3 --- 2
  //       / \   / \   .
  //      4 - 0 ---- 1 -- 7   (7 above the plane)
  //       \ /   \ /   .
  //        5 --- 6
  // Spoke 0-1 has three faces and is cut. Around 0 the ring is still one chain; but around 1
  // the ring's two faces are joined only through the cut spoke, so 1 has three fans and the
  // ring opens along 0-1 (the rule cuts every face of a non-manifold edge apart, even where
  // two of them could stay joined).
  std::vector<Vec3> positions{{0, 0, 0}};
  for (int k = 0; k < 6; ++k) {
    positions.push_back(
        {std::cos(k * std::numbers::pi / 3), std::sin(k * std::numbers::pi / 3), 0});
  }
  positions.push_back({1.5, 0, 1});
  std::vector<Triangle> faces;
  for (VertexId k = 1; k <= 6; ++k) faces.push_back({0, k, k % 6 + 1});
  faces.push_back({0, 1, 7});
  const Mesh mesh = make_mesh(positions, faces);
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  EXPECT_EQ(repaired.report.nonmanifold_vertices, 2u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 1u + 2u);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.boundary_edges, 6u + 2u + 3u);  // ring, opened spoke, extra face
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, AFaceLaidBackToBackOnASurfaceIsCutOffAlone) {
  // Two tetrahedra glued into a closed bipyramid (faces 0-5), and face 6, the reverse of face
  // 0, laid on it: each edge of face 0 has three faces (0, 6 and the bipyramid's other face
  // there). Face 0 stays joined to its neighbours; face 6 alone goes to copies, and the
  // bipyramid stays closed.
  const Mesh mesh =
      make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 1}, {0.3, 0.3, -1}},
                {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {1, 0, 4}, {2, 1, 4}, {0, 2, 4}, {0, 3, 1}});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 3u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 3u);
  EXPECT_EQ(repaired.mesh.faces[0], (Triangle{0, 1, 3}));
  EXPECT_EQ(repaired.mesh.faces[6], (Triangle{5, 7, 6}));  // copies of 0, 1, 3
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.boundary_edges, 3u);  // the laid-on face's only
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, ADoubleSidedFlapOnAnEdgeLeavesTheSurfaceJoined) {
  // The square (faces 0, 1) with a double-sided flap on its diagonal 0-2: face 2 and its
  // reverse, face 3. The diagonal has four faces; the square's two stay joined across it, the
  // flap goes to copies of 0 and 2: a closed pillow of two faces.
  const Mesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 1}},
                              {{0, 1, 2}, {0, 2, 3}, {0, 2, 4}, {0, 4, 2}});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 2u);
  EXPECT_EQ(repaired.mesh.faces[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(repaired.mesh.faces[1], (Triangle{0, 2, 3}));
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.boundary_edges, 4u);  // the square's rim
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, ADoubleSidedSurfaceKeepsEachSideJoined) {
  // A square fanned around its centre 4 (faces 0-3) and its reverse (faces 4-7): every spoke
  // holds two reverse pairs, every rim edge one (a face and its reverse, joined). Each side
  // stays joined across the spokes: one closed flat surface, its two sides meeting at the rim,
  // the centre split into a front and a back vertex (cut along every spoke, it would be four
  // closed pillows).
  const Mesh mesh =
      testing::double_sided(make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5, 0.5, 0}},
                                      {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}}));
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 4u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 1u);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, 1u);
  EXPECT_EQ(stats.boundary_edges, 0u);
  EXPECT_EQ(stats.euler_characteristic, 2);  // a sphere
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, TwoSidesJoinedThroughAFoldAreKeptApart) {
  // Two double-sided triangles on edge 0-1 (faces 0, 1 and 2, 3, each a closed pillow): side
  // with side across 0-1 would join each pillow's two faces to the other's into one fan at 0
  // and 1, where faces 0 and 2 would both use 0 -> 1. The split sees it and cuts 0-1 instead:
  // two closed pillows.
  const Mesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0.2}},
                              {{0, 1, 2}, {2, 1, 0}, {1, 3, 0}, {3, 1, 0}});
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, 2u);
  EXPECT_EQ(stats.boundary_edges, 0u);
  expect_faithful_repair(mesh, repaired);
}

TEST(RepairManifold, ManyDoubleSidedTrianglesOnOneEdgeStayClosedPillows) {
  // Twelve double-sided triangles on edge 0-1, their apexes around the edge: each a closed
  // pillow, apart from the others.
  constexpr int kPillows = 12;
  std::vector<Vec3> positions = {{0, 0, 0}, {1, 0, 0}};
  std::vector<Triangle> faces;
  for (int i = 0; i < kPillows; ++i) {
    const double angle = 2 * std::numbers::pi * i / kPillows;
    const VertexId apex = VertexId(positions.size());
    positions.push_back({0.5, std::cos(angle), std::sin(angle)});
    faces.push_back({0, 1, apex});
    faces.push_back({apex, 1, 0});
  }
  const Mesh mesh = make_mesh(positions, faces);
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, size_t(kPillows));
  EXPECT_EQ(stats.boundary_edges, 0u);
  expect_faithful_repair(mesh, repaired);
}

// The repair's check of a split: the faces on a halfedge another face holds too, at a vertex of
// a few faces and at a hub of many (whose halfedges are sorted rather than compared in pairs).
TEST(RepairManifold, FacesSharingAHalfedgeAreFoundAtSmallVerticesAndHubs) {
  constexpr VertexId kRim = 30;  // a closed fan of 30 triangles around vertex 0
  std::vector<Triangle> faces;
  for (VertexId i = 0; i < kRim; ++i) faces.push_back({0, 1 + i, 1 + (i + 1) % kRim});
  const size_t vertices = 2 + kRim;
  EXPECT_TRUE(faces_sharing_a_halfedge(faces, vertices).empty());
  // Face 30 holds 0 -> 5 as face 4 does (at the hub); face 31 holds 11 -> 12 as face 10 does
  // and 12 -> 31 alone (at a vertex of three faces).
  faces.push_back({0, 5, 31});
  faces.push_back({11, 12, 31});
  EXPECT_EQ(faces_sharing_a_halfedge(faces, vertices), (std::vector<FaceId>{4, 10, 30, 31}));
  // Three faces on one halfedge: all three.
  faces.push_back({5, 31, 0});
  EXPECT_EQ(faces_sharing_a_halfedge(faces, vertices), (std::vector<FaceId>{4, 10, 30, 31, 32}));
}

TEST(RepairManifold, MobiusStripBecomesAnOrientableStrip) {
  // A Möbius strip of k = 4 quads, top row t_i = i, bottom row b_i = 4 + i; the last quad
  // joins column 3 to column 0 with a half twist, so its face (t3, t0, b0) uses edge t0 -> b0
  // in the same direction as the first quad's face (t0, b0, b1). That one edge is cut, t0 and
  // b0 are copied, and the result is an orientable strip (a disk: Euler characteristic 1).
  //   t0 - t1 - t2 - t3 - b0
  //   |  / |  / |  / |  / |
  //   b0 - b1 - b2 - b3 - t0
  const int k = 4;
  std::vector<Vec3> positions;
  for (int i = 0; i < 2 * k; ++i) positions.push_back({double(i % k), i < k ? 1.0 : 0.0, 0.0});
  std::vector<Triangle> faces;
  for (VertexId i = 0; i + 1 < k; ++i) {
    faces.push_back({i, k + i, k + i + 1});
    faces.push_back({i, k + i + 1, i + 1});
  }
  faces.push_back({k - 1, 2 * k - 1, 0});  // (t3, b3, t0)
  faces.push_back({k - 1, 0, k});          // (t3, t0, b0)
  const Mesh mesh = make_mesh(positions, faces);
  std::string why;
  EXPECT_FALSE(is_oriented_manifold(mesh, &why));
  EXPECT_EQ(why, "edge (0, 4) is used in the same direction by faces 0 and 7");
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 2u);
  const TopologyStats stats = topology_stats(repaired.mesh);
  EXPECT_EQ(stats.components, 1u);
  EXPECT_EQ(stats.euler_characteristic, 1);
  expect_faithful_repair(mesh, repaired);
}

// ---------------------------------------------------------------------------------------
// All rules at once, twice.

Mesh everything_wrong() {
  // The book, a bowtie beside it, a duplicate, a degenerate face and an unused vertex.
  Mesh mesh = make_mesh({{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, 0, 1}, {0.5, -1, 0}},
                        {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  mesh.positions.push_back({3, 3, 3});  // 5, unused
  mesh.positions.push_back({2, 1, 0});  // 6
  mesh.positions.push_back({2, 2, 0});  // 7
  mesh.faces.push_back({2, 6, 7});      // bowtie at 2 with face 0
  mesh.faces.push_back({6, 7, 2});      // duplicate
  mesh.faces.push_back({7, 7, 6});      // degenerate
  add_vertex_texcoords(&mesh);
  return mesh;
}

TEST(Repair, EveryRuleAtOnce) {
  const Mesh mesh = everything_wrong();
  const RepairedMesh repaired = repair_in_input_order(mesh);
  EXPECT_EQ(repaired.report.degenerate_faces_removed, 1u);
  EXPECT_EQ(repaired.report.duplicate_faces_removed, 1u);
  EXPECT_EQ(repaired.report.unreferenced_vertices_removed, 1u);
  EXPECT_EQ(repaired.report.nonmanifold_edges, 1u);
  EXPECT_EQ(repaired.report.nonmanifold_vertices, 3u);
  EXPECT_EQ(repaired.report.vertex_copies_added, 5u);
  expect_faithful_repair(mesh, repaired);
}

TEST(Repair, Deterministic) {
  const Mesh mesh = everything_wrong();
  ChunkedLoops loops(4, 2, 1);
  RepairOptions chunked;
  chunked.loops = &loops;
  testing::expect_same_repair(repair_mesh(mesh, chunked), repair_mesh(mesh));
  testing::expect_same_repair(repair_in_input_order(mesh), repair_in_input_order(mesh));
  testing::expect_same_repair(repair_mesh(mesh), repair_mesh(mesh));  // rule 5 too
}

TEST(Repair, RepairIsIdempotent) {
  const RepairedMesh once = repair_in_input_order(everything_wrong());
  const RepairedMesh twice = repair_in_input_order(once.mesh);
  EXPECT_FALSE(twice.report.changed());
  EXPECT_EQ(twice.report.nonmanifold_edges, 0u);
  EXPECT_EQ(twice.mesh.faces, once.mesh.faces);
  EXPECT_EQ(twice.mesh.face_wedges, once.mesh.face_wedges);
}

// Random triangle soups over few vertices are as non-manifold as meshes get: many faces per
// edge, both directions, bowties, duplicates, degenerate faces. Whatever comes in, the output
// must be an oriented manifold that merges back into the input, and repairing it again must
// change nothing.
TEST(Repair, RandomSoupsBecomeManifolds) {
  uint64_t state = 12345;
  auto next = [&](uint32_t bound) {  // a fixed LCG: the same soups on every platform
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return uint32_t((state >> 33) % bound);
  };
  for (int round = 0; round < 200; ++round) {
    const uint32_t vertices = 3 + next(12);
    const uint32_t faces = 1 + next(40);
    Mesh mesh;
    for (uint32_t v = 0; v < vertices; ++v) {
      mesh.positions.push_back({double(next(5)), double(next(5)), double(next(5))});
    }
    for (uint32_t f = 0; f < faces; ++f) {
      mesh.faces.push_back({next(vertices), next(vertices), next(vertices)});
    }
    if (round % 2) add_vertex_texcoords(&mesh);
    SCOPED_TRACE("round " + std::to_string(round));
    const RepairedMesh repaired = repair_in_input_order(mesh);
    expect_faithful_repair(mesh, repaired);
    // In chunks side by side, ranges of a few vertices or faces: the same repair.
    ChunkedLoops loops(5, 3, 2);
    RepairOptions chunked;
    chunked.loops = &loops;
    chunked.spatial_order = false;
    testing::expect_same_repair(repair_mesh(mesh, chunked), repaired);
    RepairOptions ordered_in_chunks;  // the spatial order in chunks too
    ordered_in_chunks.loops = &loops;
    testing::expect_same_repair(repair_mesh(mesh, ordered_in_chunks), repair_mesh(mesh));
    const RepairedMesh again = repair_in_input_order(repaired.mesh);
    EXPECT_FALSE(again.report.changed());
    EXPECT_EQ(again.report.nonmanifold_edges, 0u);
    // The report agrees with the independent statistics of the input.
    const TopologyStats before = topology_stats(mesh);
    EXPECT_EQ(repaired.report.degenerate_faces_removed, before.degenerate_faces);
    if (repaired.report.duplicate_faces_removed == 0) {
      EXPECT_EQ(repaired.report.nonmanifold_edges, before.nonmanifold_edges);
      // Faces laid back to back stay joined across some of those edges: never more splits.
      EXPECT_LE(repaired.report.nonmanifold_vertices, before.nonmanifold_vertices);
    }
  }
}

TEST(Repair, EmptyMesh) {
  const RepairedMesh repaired = repair_in_input_order(Mesh{});
  EXPECT_EQ(repaired.mesh.vertex_count(), 0u);
  EXPECT_FALSE(repaired.report.changed());
}

}  // namespace
}  // namespace parapm
