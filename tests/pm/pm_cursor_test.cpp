// PmCursor: the fan rule on hand-made PMs (boundary splits, interior splits on a closed mesh,
// a fan cut by the boundary), exact undo, extraction, and corrupt splits that must throw.
#include "pm/pm_cursor.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>

#include "pm/progressive_mesh.h"
#include "pm_fixtures.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

using testing::canonical_faces;
using testing::is_oriented_manifold;

// Everything a level is made of, positions and values as bits.
struct Snapshot {
  std::vector<std::array<uint64_t, 3>> positions;
  std::vector<Triangle> faces;
  std::vector<std::array<WedgeId, 3>> face_wedges;
  std::vector<uint32_t> wedge_values;
  bool operator==(const Snapshot&) const = default;
};

Snapshot snapshot(const PmCursor& c) {
  Snapshot s;
  for (const Vec3& p : c.positions())
    s.positions.push_back({std::bit_cast<uint64_t>(p[0]), std::bit_cast<uint64_t>(p[1]),
                           std::bit_cast<uint64_t>(p[2])});
  s.faces = c.faces();
  s.face_wedges = c.face_wedges();
  for (float v : c.wedge_values()) s.wedge_values.push_back(std::bit_cast<uint32_t>(v));
  return s;
}

TEST(PmCursor, StartsAtTheBaseMesh) {
  const ProgressiveMesh pm = testing::strip_pm();
  PmCursor c(pm);
  EXPECT_EQ(c.level(), 0u);
  EXPECT_EQ(c.max_level(), 2u);
  EXPECT_EQ(c.vertex_count(), 5u);
  EXPECT_EQ(c.face_count(), 4u);
  EXPECT_EQ(c.faces(), pm.base.faces);
}

TEST(PmCursor, BoundarySplitsFollowTheFanRule) {
  const ProgressiveMesh pm = testing::strip_pm();
  PmCursor c(pm);
  c.apply_next();  // vs 1, vl 3, no vr: face 2 (1,4,3) moves to vt 5
  const std::vector<Triangle> level1 = {{0, 1, 2}, {1, 3, 2}, {5, 4, 3}, {3, 4, 2}, {1, 5, 3}};
  EXPECT_EQ(c.faces(), level1);
  EXPECT_EQ(c.positions()[1], (Vec3{1, 0, 0}));
  EXPECT_EQ(c.positions()[5], (Vec3{2, 0, 0}));
  c.apply_next();  // vs 2, no vl, vr 3: face 3 (3,4,2) moves to vt 6
  EXPECT_EQ(c.faces(), testing::strip_full_faces());
  EXPECT_TRUE(is_oriented_manifold(c.faces()));
  EXPECT_EQ(c.vertex_count(), 7u);
  EXPECT_THROW(c.apply_next(), Error);
}

TEST(PmCursor, InteriorSplitsKeepAClosedManifold) {
  const ProgressiveMesh pm = testing::octahedron_pm();
  PmCursor c(pm);
  c.apply_next();
  // The fan (0,2,4), (2,1,4) moved to 6; fl = (4,6,1), fr = (6,4,0).
  EXPECT_EQ(c.faces()[0], (Triangle{0, 2, 6}));
  EXPECT_EQ(c.faces()[1], (Triangle{2, 1, 6}));
  EXPECT_EQ(c.faces()[8], (Triangle{4, 6, 1}));
  EXPECT_EQ(c.faces()[9], (Triangle{6, 4, 0}));
  EXPECT_EQ(c.faces_of(6).size(), 4u);
  EXPECT_EQ(c.faces_of(4).size(), 4u);
  while (c.level() < c.max_level()) {
    c.apply_next();
    // Closed: every directed edge once, and its reverse too; Euler characteristic 2.
    EXPECT_TRUE(is_oriented_manifold(c.faces()));
    EXPECT_EQ(c.vertex_count() + c.face_count() - c.face_count() * 3 / 2, 2u);
  }
  EXPECT_EQ(c.faces()[1], (Triangle{2, 1, 8}));  // split 2 moved it again, from 6 to 8
  EXPECT_EQ(c.faces()[8], (Triangle{4, 8, 1}));  // and fl of split 0 with it
}

TEST(PmCursor, FanCutByTheBoundaryIsWalkedFromBothEnds) {
  const ProgressiveMesh pm = testing::cut_fan_pm();
  PmCursor c(pm);
  c.apply_next();
  EXPECT_EQ(c.faces(), testing::cut_fan_full_faces());
  EXPECT_TRUE(is_oriented_manifold(c.faces()));
  // vs is interior now: 5 faces around it forming a cycle; vt has 4 faces.
  EXPECT_EQ(c.faces_of(2).size(), 5u);
  EXPECT_EQ(c.faces_of(7).size(), 4u);
}

TEST(PmCursor, UndoRestoresEveryLevelExactly) {
  std::vector<ProgressiveMesh> pms = {testing::strip_pm(), testing::octahedron_pm(true),
                                      testing::cut_fan_pm()};
  for (bool closed : {true, false})
    for (bool attributes : {false, true})
      for (bool float32 : {true, false})
        pms.push_back(testing::random_pm(300, {closed, attributes, float32, 7}));
  for (const ProgressiveMesh& pm : pms) {
    PmCursor c(pm);
    std::vector<Snapshot> levels = {snapshot(c)};
    while (c.level() < c.max_level()) {
      c.apply_next();
      levels.push_back(snapshot(c));
    }
    while (c.level() > 0) {
      c.undo_last();
      ASSERT_EQ(snapshot(c), levels[c.level()]) << "level " << c.level();
    }
    EXPECT_THROW(c.undo_last(), Error);
    // Random jumps between levels.
    std::mt19937 rng(3);
    for (int jump = 0; jump < 20; ++jump) {
      const size_t level = rng() % (pm.splits.size() + 1);
      c.go_to_level(level);
      ASSERT_EQ(snapshot(c), levels[level]) << "level " << level;
    }
    EXPECT_THROW(c.go_to_level(pm.splits.size() + 1), Error);
  }
}

TEST(PmCursor, RandomPmsStayManifold) {
  for (bool closed : {true, false}) {
    const ProgressiveMesh pm = testing::random_pm(500, {closed, false, true, 11});
    EXPECT_NO_THROW(validate_pm(pm));
    PmCursor c(pm);
    c.go_to_level(pm.splits.size());
    EXPECT_TRUE(is_oriented_manifold(c.faces()));
    EXPECT_EQ(c.face_count(), pm.full_face_count());
  }
}

TEST(PmCursor, ExtractGivesTheLevelWithConsistentWedges) {
  const ProgressiveMesh pm = testing::octahedron_pm(true);
  PmCursor c(pm);
  Mesh base = c.extract();
  EXPECT_EQ(base.face_count(), 8u);
  EXPECT_EQ(base.wedge_count(), 6u);
  EXPECT_TRUE(base.positions_are_float);
  c.apply_next();
  const Mesh m = c.extract();
  EXPECT_EQ(m.vertex_count(), 7u);
  EXPECT_EQ(m.face_count(), 10u);
  // PM wedge 4 is used at vertex 4 (kept faces, fl) and at vertex 6 (the moved faces keep
  // their corner wedges): two wedges in the Mesh. Wedges 0..7 exist: 9 pairs.
  EXPECT_EQ(m.wedge_count(), 9u);
  for (FaceId f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.wedge_vertex[m.face_wedges[f][k]], m.faces[f][k]);
  // Face 0 (0,2,6) kept PM wedges (0,2,4); wedge 4 changed to (1/2, 5/8) at this level.
  const float* w = m.wedge(m.face_wedges[0][2]);
  EXPECT_EQ(w[0], 0.5f);
  EXPECT_EQ(w[1], 0.625f);
}

TEST(PmCursor, ExtractDropsUnusedWedges) {
  ProgressiveMesh pm = testing::octahedron_pm(true);
  pm.base.wedge_vertex.push_back(0);  // a wedge no corner uses
  pm.base.wedge_values.insert(pm.base.wedge_values.end(), {9.0f, 9.0f});
  // Shift the new wedge ids by one, as the PM now has 7 base wedges.
  for (VertexSplit& s : pm.splits)
    for (WedgeId& w : s.corner_wedges)
      if (w != kNoId && w >= 6) ++w;
  for (WedgeChange& change : pm.wedge_changes)
    if (change.wedge >= 6) ++change.wedge;
  ASSERT_NO_THROW(validate_pm(pm));
  PmCursor c(pm);
  EXPECT_EQ(c.wedge_count(), 7u);
  EXPECT_EQ(c.extract().wedge_count(), 6u);
}

// A component whose last triangle was collapsed away: two faceless base vertices, and the
// split that brings the triangle back as fl (vr absent) or fl and fr; undone, they are faceless
// again.
TEST(PmCursor, SplitOfAFacelessVertexBringsAComponentBack) {
  for (bool with_fr : {false, true}) {
    ProgressiveMesh pm;
    pm.base.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}, {6, 5, 5}, {5, 6, 5}};
    pm.base.faces = {{3, 4, 5}};  // vertices 0, 1, 2 have no faces
    VertexSplit s;
    s.vs = 0;
    s.vl = 1;
    s.vr = with_fr ? 2 : kNoId;
    s.vs_before = s.vs_after = {0, 0, 0};
    s.vt_after = {1, 1, 0};
    pm.splits.push_back(s);
    validate_pm(pm);
    PmCursor c(pm);
    const Snapshot base = snapshot(c);
    c.apply_next();
    std::vector<Triangle> fine = {{3, 4, 5}, {0, 6, 1}};
    if (with_fr) fine.push_back({6, 0, 2});
    EXPECT_EQ(c.faces(), fine);
    EXPECT_TRUE(is_oriented_manifold(c.faces()));
    c.undo_last();
    EXPECT_EQ(snapshot(c), base);
  }
}

TEST(PmCursor, SplitOfAFacelessVertexTowardsOneWithFacesThrows) {
  ProgressiveMesh pm;
  pm.base.positions = {{0, 0, 0}, {5, 5, 5}, {6, 5, 5}, {5, 6, 5}};
  pm.base.faces = {{1, 2, 3}};
  VertexSplit s;
  s.vs = 0;
  s.vl = 1;  // has a face: the new face would hang off another component's vertex
  pm.splits.push_back(s);
  PmCursor c(pm);
  const Snapshot before = snapshot(c);
  EXPECT_THROW(c.apply_next(), Error);
  EXPECT_EQ(snapshot(c), before);
}

// Corrupt splits: the cursor throws and stays where it was; nothing loops.
TEST(PmCursor, SplitWithVlNotAdjacentThrows) {
  ProgressiveMesh pm = testing::octahedron_pm();
  pm.splits.resize(1);
  pm.splits[0].vl = 5;  // the bottom vertex: not a neighbour of the top one
  PmCursor c(pm);
  const Snapshot before = snapshot(c);
  EXPECT_THROW(c.apply_next(), Error);
  EXPECT_EQ(c.level(), 0u);
  EXPECT_EQ(snapshot(c), before);
}

TEST(PmCursor, BoundarySplitOfAnInteriorVertexThrows) {
  // vr absent means vs-vt is a boundary edge, impossible for an interior vs: the clockwise
  // walk would circle vs forever.
  ProgressiveMesh pm = testing::octahedron_pm();
  pm.splits.resize(1);
  pm.splits[0].vr = kNoId;
  PmCursor c(pm);
  EXPECT_THROW(c.apply_next(), Error);
  pm.splits[0].vr = 0;
  pm.splits[0].vl = kNoId;
  PmCursor c2(pm);
  EXPECT_THROW(c2.apply_next(), Error);
}

TEST(PmCursor, OutOfRangeIdsThrowWithoutValidation) {
  ProgressiveMesh pm = testing::strip_pm();
  pm.splits[1].vs = 6;  // vt of split 1 itself
  PmCursor c(pm);
  c.apply_next();
  try {
    c.apply_next();
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("vsplit 1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(c.level(), 1u);
}

TEST(PmCursor, HighValenceVertexUsesTheSortedIndex) {
  // A fan of 200 triangles around vertex 0 (a disk), split in half repeatedly.
  ProgressiveMesh pm;
  const int n = 200;
  pm.base.positions.push_back({0, 0, 0});
  for (int i = 0; i < n; ++i)
    pm.base.positions.push_back({std::cos(i * 0.0314), std::sin(i * 0.0314), 0});
  for (int i = 0; i < n; ++i)
    pm.base.faces.push_back({0, VertexId(1 + i), VertexId(1 + (i + 1) % n)});
  VertexSplit s;
  s.vs = 0;
  s.vr = 1;
  s.vl = 101;  // faces 0..99 move
  s.vs_before = s.vs_after = s.vt_after = {0, 0, 0};
  pm.splits.push_back(s);
  ASSERT_NO_THROW(validate_pm(pm));
  PmCursor c(pm);
  c.apply_next();
  EXPECT_EQ(c.faces_of(0).size(), 102u);
  EXPECT_EQ(c.faces_of(201).size(), 102u);
  EXPECT_TRUE(is_oriented_manifold(c.faces()));
  for (FaceId f = 0; f < 100; ++f) EXPECT_EQ(c.faces()[f][0], 201u);
  c.undo_last();
  EXPECT_EQ(c.faces(), pm.base.faces);
}

}  // namespace
}  // namespace parapm
