// Legality rules of the collapse engine, one tiny drawn mesh per rule.
#include <gtest/gtest.h>

#include "simplify/collapse_mesh.h"
#include "simplify/modules.h"

namespace parapm {
namespace {

Mesh make_mesh(std::vector<Vec3> positions, std::vector<Triangle> faces) {
  Mesh m;
  m.positions = std::move(positions);
  m.faces = std::move(faces);
  return m;
}

// Which standard constraint (by name) vetoes collapsing vt into vs at vs's position; "" if none.
std::string veto(const Mesh& mesh, VertexId vs, VertexId vt, std::vector<uint8_t> locked = {},
                 bool components_may_vanish = false) {
  CollapseMesh cm(mesh);
  auto modules = standard_constraints(locked, {}, components_may_vanish);
  for (auto& m : modules) m->initialize(cm);
  CollapseCandidate c;
  c.vs = vs;
  c.vt = vt;
  c.position = cm.position(vs);
  const EdgeFaces edge = cm.edge_faces(vs, vt);
  for (auto& m : modules)
    if (!m->allows(cm, c, edge)) return m->name();
  return "";
}

Mesh tetrahedron() {
  return make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                   {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}});
}

Mesh octahedron() {
  return make_mesh(
      {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
      {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}});
}

TEST(Legality, TetrahedronCannotCollapse) {
  EXPECT_EQ(veto(tetrahedron(), 0, 1), "component-minimum");
}

// Two lone triangles, a large and a small one: each keeps its triangle, unless components may
// vanish; then the small one's may collapse away, never the largest one's (the mesh never
// vanishes whole), nor one touching another component.
TEST(Legality, OnlyTheLargestOpenComponentKeepsItsLastTriangleWhenComponentsMayVanish) {
  const Mesh m = make_mesh({{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {20, 0, 0}, {21, 0, 0}, {20, 1, 0}},
                           {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(veto(m, 3, 4), "component-minimum");
  EXPECT_EQ(veto(m, 0, 1), "component-minimum");
  EXPECT_EQ(veto(m, 3, 4, {}, true), "");
  EXPECT_EQ(veto(m, 0, 1, {}, true), "component-minimum");
  // A closed component keeps its tetrahedron either way.
  EXPECT_EQ(veto(tetrahedron(), 0, 1, {}, true), "component-minimum");
  // So does a piece with a vertex where another component has one (an unwelded soup's
  // triangle: losing it would open a hole in the surface the pieces make together).
  Mesh touching = m;
  touching.positions[3] = touching.positions[1];
  EXPECT_EQ(veto(touching, 3, 4, {}, true), "component-minimum");
}

// The collapse of a lone triangle's edge leaves its three vertices without faces: not alive.
TEST(Legality, CollapsingALoneTriangleLeavesNoLiveVertex) {
  CollapseMesh cm(make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}}));
  cm.collapse(0, 1, {0.5, 0, 0}, cm.edge_faces(0, 1));
  EXPECT_EQ(cm.live_faces(), 0u);
  EXPECT_EQ(cm.live_vertices(), 0u);
  for (VertexId v : {0u, 1u, 2u}) EXPECT_FALSE(cm.vertex_alive(v)) << v;
  EXPECT_EQ(cm.position(0), (Vec3{0.5, 0, 0}));
}

TEST(Legality, OctahedronEdgeCollapses) { EXPECT_EQ(veto(octahedron(), 0, 2), ""); }

//   c
//  / \      the triangle (a, b, c) is a hole, not a face; d lies below a-b.
// a---b     a and b share the neighbour c, which is not an apex of edge a-b's only face
//  \ /      (b, a, d): collapsing a-b would glue the hole shut into a non-manifold edge.
//   d
// The outer ring e, f, g closes the fan around c so that a-c and b-c are boundary edges
// of the hole only.
TEST(Legality, LinkConditionForbidsClosingAHole) {
  const Mesh m = make_mesh({{0, 0, 0}, {2, 0, 0}, {1, 2, 0}, {1, -1, 0}, {-1, 3, 0}, {3, 3, 0}},
                           {{1, 0, 3}, {0, 2, 4}, {2, 1, 5}, {4, 2, 5}});
  EXPECT_EQ(veto(m, 0, 1), "link-condition");
}

//  a---c
//  | / |    edge b-c is interior (two faces), but b and c are both boundary vertices:
//  b---d    collapsing it would pinch the strip into two sheets joined at one vertex.
TEST(Legality, InteriorEdgeBetweenBoundaryVertices) {
  const Mesh m = make_mesh({{0, 1, 0}, {0, 0, 0}, {1, 1, 0}, {1, 0, 0}}, {{0, 1, 2}, {1, 3, 2}});
  EXPECT_EQ(veto(m, 1, 2), "boundary");
  EXPECT_EQ(veto(m, 0, 1), "");  // a boundary edge between boundary vertices is fine
}

TEST(Legality, LockedVertexIsNeverRemoved) {
  std::vector<uint8_t> locked(6, 0);
  locked[2] = 1;
  EXPECT_EQ(veto(octahedron(), 0, 2, locked), "locked-vertices");
  EXPECT_EQ(veto(octahedron(), 2, 0, locked), "");
}

// A seam collapse's collapse (CollapseCandidate::seam) may remove and move locked copies: the
// simplifier keeps each group of copies at one place.
TEST(Legality, SeamCollapseMayRemoveAndMoveALockedCopy) {
  std::vector<uint8_t> locked(6, 0);
  locked[0] = locked[2] = 1;
  CollapseMesh cm(octahedron());
  auto modules = standard_constraints(locked);
  for (auto& m : modules) m->initialize(cm);
  CollapseCandidate c;
  c.vs = 0;
  c.vt = 2;
  c.position = {0.5, 0.5, 0};
  const EdgeFaces edge = cm.edge_faces(0, 2);
  EXPECT_FALSE(modules[0]->allows(cm, c, edge)) << modules[0]->name();
  c.seam = true;
  for (auto& m : modules) EXPECT_TRUE(m->allows(cm, c, edge)) << m->name();
}

// drop_too_small: of a seam collapse's collapses, those in a component that would fall below
// its smallest form once the ones before them were made stay out; the others go on.
TEST(Legality, SeamCollapsesInAComponentTooSmallToShrinkAreDropped) {
  // A lone triangle (vertices 0-2) and a strip of two triangles (3-6, four vertices).
  const Mesh m =
      make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 0, 0}, {6, 0, 0}, {5, 1, 0}, {6, 1, 0}},
                {{0, 1, 2}, {3, 4, 5}, {4, 6, 5}});
  CollapseMesh cm(m);
  auto modules = standard_constraints({});
  for (auto& mod : modules) mod->initialize(cm);
  std::vector<SeamPair> collapses{{0, 1}, {3, 4}, {5, 6}};
  for (auto& mod : modules) mod->drop_too_small(cm, collapses);
  // The triangle is at its smallest form; the strip affords one collapse, not two.
  ASSERT_EQ(collapses.size(), 1u);
  EXPECT_EQ(collapses[0].vt, 4u);
}

//     c           Moving b onto a' (far left of a) flips face (b, d, c)... here we collapse
//    /|\          d into a, which drags the fan around d across the edge b-c.
//   a-b-d  flat strip below: faces (a,b,c), (b,d,c), (a,e,b), (b,e,d)
//    \|/
//     e
TEST(Legality, CollapseThatFlipsAFaceIsVetoed) {
  const Mesh m = make_mesh({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 0, 0}, {1, -1, 0}},
                           {{0, 1, 2}, {1, 3, 2}, {0, 4, 1}, {1, 4, 3}});
  // Collapsing b (interior) into d at d's position is fine: the fan just shrinks.
  EXPECT_EQ(veto(m, 3, 1), "");
  CollapseMesh cm(m);
  auto modules = standard_constraints({});
  for (auto& mod : modules) mod->initialize(cm);
  CollapseCandidate c;
  c.vs = 1;  // b stays, d goes, but b is placed beyond a: faces around b fold over
  c.vt = 3;
  c.position = {-1, 0.2, 0};
  const EdgeFaces edge = cm.edge_faces(1, 3);
  std::string vetoed;
  for (auto& mod : modules)
    if (!mod->allows(cm, c, edge)) {
      vetoed = mod->name();
      break;
    }
  EXPECT_EQ(vetoed, "face-geometry");
}

}  // namespace
}  // namespace parapm
