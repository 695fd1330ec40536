// Geomorphs: both ends exact, ancestors from the coarse level (not from creation time).
#include "pm/geomorph.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm_fixtures.h"
#include "test_support.h"
#include "util/error.h"

namespace parapm {
namespace {

using testing::canonical_faces;

// Faces of the fine mesh written with ancestors, degenerate ones dropped.
std::vector<Triangle> ancestor_faces(const Geomorph& g) {
  std::vector<Triangle> faces;
  for (const Triangle& t : g.fine.faces) {
    const Triangle a = {g.ancestor[t[0]], g.ancestor[t[1]], g.ancestor[t[2]]};
    if (a[0] != a[1] && a[1] != a[2] && a[2] != a[0]) faces.push_back(a);
  }
  return faces;
}

TEST(Geomorph, AncestorsAndCoarsePositions) {
  const ProgressiveMesh pm = testing::octahedron_pm();
  const Geomorph g = make_geomorph(pm, 0, 3);
  EXPECT_EQ(g.ancestor, (std::vector<VertexId>{0, 1, 2, 3, 4, 5, 4, 5, 4}));
  // Vertex 8 was split off 6 (created at (0, 1/4, 1)), whose ancestor 4 is at (0,0,1) in the
  // base mesh: 8 starts there, not where 6 was when 8 was created.
  EXPECT_EQ(g.coarse_positions[8], (Vec3{0, 0, 1}));
  EXPECT_EQ(g.coarse_positions[4], (Vec3{0, 0, 1}));  // 4 itself moved at split 0
  EXPECT_EQ(g.coarse_positions[7], (Vec3{0, 0, -1}));

  const Geomorph h = make_geomorph(pm, 1, 3);
  EXPECT_EQ(h.ancestor[8], 6u);
  EXPECT_EQ(h.coarse_positions[8], (Vec3{0, 0.25, 1}));  // 6 at level 1
  EXPECT_EQ(h.coarse_positions[4], (Vec3{0, -0.25, 1}));
}

TEST(Geomorph, EndpointsAreExact) {
  std::vector<ProgressiveMesh> pms = {testing::octahedron_pm(true), testing::strip_pm(),
                                      testing::cut_fan_pm()};
  pms.push_back(testing::random_pm(300, {false, true, false, 4}));
  pms.push_back(testing::random_pm(300, {true, false, true, 5}));
  for (const ProgressiveMesh& pm : pms) {
    const size_t n = pm.splits.size();
    for (auto [coarse, fine] : {std::pair<size_t, size_t>{0, n}, {n / 3, n}, {0, n / 2}, {1, 1}}) {
      const Geomorph g = make_geomorph(pm, coarse, fine);
      const Mesh fine_mesh = level_of_detail(pm, fine);
      const Mesh at1 = g.at(1);
      const MeshDifference d1 = compare_meshes_exact(at1, fine_mesh, true);
      EXPECT_TRUE(d1.equal) << d1.first_difference;
      EXPECT_EQ(at1.positions_are_float, pm.base.positions_are_float);

      // alpha = 0: every vertex at its ancestor's coarse position, bit for bit; without the
      // zero-area faces, the coarse level's faces.
      const Mesh coarse_mesh = level_of_detail(pm, coarse);
      const Mesh at0 = g.at(0);
      for (VertexId v = 0; v < at0.vertex_count(); ++v)
        for (int k = 0; k < 3; ++k)
          ASSERT_EQ(std::bit_cast<uint64_t>(at0.positions[v][k]),
                    std::bit_cast<uint64_t>(coarse_mesh.positions[g.ancestor[v]][k]));
      EXPECT_EQ(canonical_faces(ancestor_faces(g)), canonical_faces(coarse_mesh.faces));
      EXPECT_EQ(at0.faces, fine_mesh.faces);
    }
  }
}

TEST(Geomorph, InterpolatesLinearly) {
  const ProgressiveMesh pm = testing::octahedron_pm(true);
  const Geomorph g = make_geomorph(pm, 0, 3);
  const Mesh half = g.at(0.5);
  EXPECT_EQ(half.positions[8], (Vec3{-0.0625, 0.1875, 1}));  // (0,0,1) -> (-1/8, 3/8, 1)
  EXPECT_FALSE(half.positions_are_float);
  // Wedge values: PM wedge 4 changed from (1/2, 1/2) to (1/2, 5/8) at split 0; at 0.5 it is
  // halfway. Wedges introduced after the coarse level keep their fine values.
  const Mesh fine = g.at(1);
  for (WedgeId w = 0; w < half.wedge_count(); ++w) {
    const float* coarse = g.coarse_wedge_values.data() + 2 * w;
    for (int k = 0; k < 2; ++k)
      EXPECT_EQ(half.wedge(w)[k], float(0.5 * coarse[k] + 0.5 * fine.wedge(w)[k]));
  }
  bool found_changed = false;
  for (WedgeId w = 0; w < half.wedge_count(); ++w)
    if (fine.wedge(w)[1] == 0.625f && g.coarse_wedge_values[2 * w + 1] == 0.5f) {
      found_changed = true;
      EXPECT_EQ(half.wedge(w)[1], 0.5625f);
    }
  EXPECT_TRUE(found_changed);
}

TEST(Geomorph, RejectsBadArguments) {
  const ProgressiveMesh pm = testing::octahedron_pm();
  EXPECT_THROW(make_geomorph(pm, 2, 1), Error);
  EXPECT_THROW(make_geomorph(pm, 0, 4), Error);
  const Geomorph g = make_geomorph(pm, 0, 3);
  EXPECT_THROW(g.at(-0.01), Error);
  EXPECT_THROW(g.at(1.01), Error);
  EXPECT_THROW(g.at(std::nan("")), Error);
}

}  // namespace
}  // namespace parapm
