// The energy metric's pieces on drawn meshes: point projection, surface samples, the spring
// schedule, the least-squares placement, and the point bookkeeping through collapses.
#include <gtest/gtest.h>

#include <cmath>

#include "drawn_meshes.h"
#include "mesh/repair.h"
#include "simplify/energy_priority.h"
#include "simplify/point_projection.h"
#include "simplify/sharp_curves.h"
#include "simplify/simplifier.h"
#include "simplify/surface_samples.h"

namespace parapm {
namespace {

constexpr double kTight = 1e-12;

TEST(PointProjection, InsideAPlaneProjectsStraightDown) {
  const Projection p = project_on_triangle({0.25, 0.25, 2}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  EXPECT_NEAR(p.distance_sq, 4, kTight);
  EXPECT_NEAR(p.bary[0], 0.5, kTight);
  EXPECT_NEAR(p.bary[1], 0.25, kTight);
  EXPECT_NEAR(p.bary[2], 0.25, kTight);
}

TEST(PointProjection, OutsideLandsOnTheNearestEdgeOrCorner) {
  // Beyond edge (1,0)-(0,1): the closest point is its midpoint.
  Projection p = project_on_triangle({1, 1, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  EXPECT_NEAR(p.distance_sq, 0.5, kTight);
  EXPECT_NEAR(p.bary[1], 0.5, kTight);
  EXPECT_NEAR(p.bary[2], 0.5, kTight);
  // Behind corner a.
  p = project_on_triangle({-1, -2, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  EXPECT_NEAR(p.distance_sq, 6, kTight);
  EXPECT_NEAR(p.bary[0], 1, kTight);
  // A degenerate triangle (three points on a line) is its longest segment.
  p = project_on_triangle({0.5, 1, 0}, {0, 0, 0}, {1, 0, 0}, {2, 0, 0});
  EXPECT_NEAR(p.distance_sq, 1, kTight);
}

TEST(PointProjection, PreparedTriangleAgreesWithTheReference) {
  SplitMix64 random(7);
  auto coordinate = [&] { return random.uniform() * 4 - 2; };
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3 a{coordinate(), coordinate(), coordinate()};
    const Vec3 b{coordinate(), coordinate(), coordinate()};
    const Vec3 c{coordinate(), coordinate(), coordinate()};
    const Vec3 x{coordinate(), coordinate(), coordinate()};
    const Projection reference = project_on_triangle(x, a, b, c);
    const Projection fast = PreparedTriangle(a, b, c).project(x);
    ASSERT_NEAR(fast.distance_sq, reference.distance_sq, 1e-9 * (1 + reference.distance_sq))
        << "trial " << trial;
    // The barycentric coordinates give back the closest point.
    Vec3 q{};
    for (int k = 0; k < 3; ++k)
      q[k] = fast.bary[0] * a[k] + fast.bary[1] * b[k] + fast.bary[2] * c[k];
    const Vec3 d = sub(x, q);
    ASSERT_NEAR(dot(d, d), fast.distance_sq, 1e-9 * (1 + fast.distance_sq)) << "trial " << trial;
  }
}

TEST(PointProjection, SegmentClampsToItsEnds) {
  EXPECT_NEAR(project_on_segment({0.5, 1, 0}, {0, 0, 0}, {1, 0, 0}).t, 0.5, kTight);
  EXPECT_EQ(project_on_segment({-3, 0, 0}, {0, 0, 0}, {1, 0, 0}).t, 0);
  EXPECT_NEAR(project_on_segment({3, 0, 0}, {0, 0, 0}, {1, 0, 0}).distance_sq, 4, kTight);
}

TEST(SpringConstant, FadesAsPointsAccumulate) {
  EXPECT_EQ(spring_constant(0), 1e-2);
  EXPECT_EQ(spring_constant(3.9), 1e-2);
  EXPECT_EQ(spring_constant(4), 1e-4);
  EXPECT_EQ(spring_constant(7.9), 1e-4);
  EXPECT_EQ(spring_constant(8), 1e-8);
  double previous = spring_constant(0);
  for (double r = 0; r < 100; r += 0.25) {
    EXPECT_LE(spring_constant(r), previous);
    previous = spring_constant(r);
  }
}

// A roof: two planes meeting along the ridge y = 0 (z = -|y| / 2), as a 5 x 5 grid whose
// triangles never cross the ridge.
Mesh roof() {
  Mesh m;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i) {
      const double x = i - 2, y = j - 2;
      m.positions.push_back({x, y, -0.5 * std::abs(y)});
    }
  auto id = [](int i, int j) { return VertexId(j * 5 + i); };
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      m.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

TEST(SurfaceSamples, OnePerVertexThenAreaWeightedOnTheirFaces) {
  const Mesh mesh = roof();
  const CollapseMesh cm(mesh);
  const auto samples = sample_surface(cm, 3.0, 42);
  ASSERT_EQ(samples.size(), mesh.vertex_count() + 3 * mesh.face_count());
  for (size_t i = 0; i < samples.size(); ++i) {
    const SurfaceSample& s = samples[i];
    if (i < mesh.vertex_count()) {
      EXPECT_EQ(s.vertex, i);
      EXPECT_EQ(s.position, mesh.positions[i]);
    } else {
      EXPECT_EQ(s.vertex, kNoId);
    }
    const Triangle& t = mesh.faces[s.face];
    EXPECT_LT(project_on_triangle(s.position, mesh.positions[t[0]], mesh.positions[t[1]],
                                  mesh.positions[t[2]])
                  .distance_sq,
              1e-24)
        << "sample " << i << " is on its face";
  }
  const auto again = sample_surface(cm, 3.0, 42);
  const auto other = sample_surface(cm, 3.0, 43);
  for (size_t i = 0; i < samples.size(); ++i) EXPECT_EQ(samples[i].position, again[i].position);
  EXPECT_NE(samples.back().position, other.back().position) << "the seed changes the draw";
}

// The bucketed search finds what a search of the whole list finds: random targets, every
// cumulative value and its neighbours (a bucket's edges fall on them or between), ties, the
// ends, and lists from one face to a hundred thousand.
TEST(SurfaceSamples, AreaIndexFindsWhatUpperBoundFinds) {
  SplitMix64 random(5);
  for (size_t n : {size_t(1), size_t(15), size_t(16), size_t(17), size_t(1000), size_t(100000)}) {
    std::vector<double> cumulative;
    double total = 0;
    for (size_t i = 0; i < n; ++i) {
      // Areas over six orders of magnitude, some repeated (equal running sums do not occur,
      // but equal steps do).
      const double area = i % 7 == 3 ? 1.0 : std::pow(10.0, 6 * random.uniform() - 3);
      total += area;
      cumulative.push_back(total);
    }
    const AreaIndex index(cumulative);
    auto check = [&](double target) {
      const size_t expected = size_t(
          std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin());
      ASSERT_EQ(index.first_above(target), expected) << "n = " << n << ", target " << target;
    };
    for (int i = 0; i < 20000; ++i) check(random.uniform() * total);
    for (double c : cumulative) {
      check(c);
      check(std::nextafter(c, 0.0));
      check(std::nextafter(c, 2 * total));
    }
    for (double t : {0.0, total, 2 * total, -1.0}) check(t);
    if (HasFatalFailure()) return;
  }
}

TEST(SurfaceSamples, DrawnInChunksSideBySideTheSamePoints) {
  const Mesh mesh = roof();
  const CollapseMesh cm(mesh);
  ChunkedLoops loops(5, 3, 2);
  const auto whole = sample_surface(cm, 7.0, 42);
  const auto chunked = sample_surface(cm, 7.0, 42, loops);
  ASSERT_EQ(whole.size(), chunked.size());
  for (size_t i = 0; i < whole.size(); ++i) {
    EXPECT_EQ(whole[i].position, chunked[i].position) << i;
    EXPECT_EQ(whole[i].face, chunked[i].face) << i;
    EXPECT_EQ(whole[i].vertex, chunked[i].vertex) << i;
  }
  SplitMix64 stepped(9);
  for (int i = 0; i < 5; ++i) stepped.next();
  EXPECT_EQ(SplitMix64::at(9, 5).next(), stepped.next());
}

TEST(EnergyPriority, LeastSquaresPlacesTheVertexOnTheRidge) {
  const Mesh mesh = roof();
  CollapseMesh cm(mesh);
  EnergyOptions options;
  options.samples_per_face = 8;  // points on both planes, near the ridge too
  EnergyPriority energy({}, options);
  energy.initialize(cm);
  // Ridge vertices (2, 2) and (3, 2) of the grid: the surface stays exact only if the merged
  // vertex stays on the ridge line.
  const VertexId a = 2 * 5 + 2, b = 2 * 5 + 3;
  // (On it up to the springs' pull: with 8 points per face kappa is 1e-8, which moves the
  // optimum by a few 1e-9 towards the ring's centroid.)
  CollapseCandidate c;
  ASSERT_TRUE(energy.evaluate(cm, a, b, c, Costing::kPerform));
  EXPECT_NEAR(c.position[1], 0, 1e-7);
  EXPECT_NEAR(c.position[2], 0, 1e-7);
  EXPECT_GE(c.position[0], 0 - 1e-7);
  EXPECT_LE(c.position[0], 1 + 1e-7);
  EXPECT_LT(c.error, 1e-7) << "every point is still on the surface";
  EXPECT_LT(c.cost, 1e-6) << "only the springs change, at kappa 1e-8";

  // Across the ridge, from a ridge vertex to a vertex of the slope, the best placement is
  // the ridge vertex itself (again exact); halfway down the slope it would not be.
  const VertexId down = 3 * 5 + 2;
  ASSERT_TRUE(energy.evaluate(cm, a, down, c, Costing::kPerform));
  EXPECT_NEAR(c.position[1], 0, 1e-7);
  EXPECT_LT(c.error, 1e-7);
  // Collapsing two slope vertices off the ridge keeps every point on the surface too, but a
  // placement off the slope's plane would not: the solve keeps it in the plane.
  const VertexId slope_a = 3 * 5 + 1, slope_b = 3 * 5 + 2;
  ASSERT_TRUE(energy.evaluate(cm, slope_a, slope_b, c, Costing::kPerform));
  EXPECT_NEAR(c.position[2], -0.5 * std::abs(c.position[1]), 1e-7);
}

TEST(EnergyPriority, PointsFollowTheirFacesThroughCollapses) {
  // A bumpy closed surface (a sphere with a ripple), simplified a long way: afterwards every
  // point is on a live face, and its stored distance is its distance to that face.
  const Mesh m = testing::uv_sphere(14, 20, 0.1);
  CollapseMesh cm(m);
  EnergyOptions options;
  options.samples_per_face = 2;
  EnergyPriority energy({}, options);
  Simplifier simplifier(cm, energy, standard_constraints({}));
  const auto records = simplifier.run({60}, {}, nullptr);
  ASSERT_LE(cm.live_faces(), 60u);
  ASSERT_EQ(energy.point_count(), m.vertex_count() + 2 * m.face_count());
  double worst = 0;
  size_t parked = 0;
  const auto states = energy.point_states();
  for (size_t i = 0; i < states.size(); ++i) {
    const auto& point = states[i];
    if (const VertexId v = point.parked; v != kNoId) {
      // Parked: the sample of a vertex that never moved, on the mesh by construction.
      ASSERT_TRUE(cm.vertex_alive(v));
      ASSERT_EQ(point.position, cm.position(v));
      ASSERT_EQ(point.distance_sq, 0);
      ++parked;
      continue;
    }
    const FaceId f = point.face;
    ASSERT_NE(f, kNoId) << "point " << i << " is on no face";
    ASSERT_TRUE(cm.face_alive(f)) << "point " << i;
    const Triangle& t = cm.face(f);
    const double d =
        project_on_triangle(point.position, cm.position(t[0]), cm.position(t[1]), cm.position(t[2]))
            .distance_sq;
    ASSERT_NEAR(point.distance_sq, d, 1e-12) << "point " << i;
    worst = std::max(worst, std::sqrt(d));
  }
  // The error a record carries is the largest distance of its star's points once performed,
  // so the largest recorded error bounds every point's distance at the end.
  float recorded = 0;
  for (const CollapseRecord& r : records) recorded = std::max(recorded, r.error);
  EXPECT_LE(worst, double(recorded) * (1 + 1e-6));
  EXPECT_GT(worst, 0);
  EXPECT_LT(parked, cm.live_vertices()) << "most survivors moved";
}

// The volume term (EnergyOptions::volume_weight), weighted far above the rest, places every
// collapse of a closed sphere where the enclosed volume does not change; without it the
// points and springs pull each merged vertex inwards, onto the chords.
TEST(EnergyPriority, VolumeTermKeepsTheEnclosedVolume) {
  const Mesh sphere = testing::uv_sphere(14, 20);
  const CollapseMesh cm(sphere);
  auto volume = [](const CollapseMesh& m) {
    double sum = 0;
    for (FaceId f = 0; f < m.face_capacity(); ++f)
      if (m.face_alive(f)) {
        const Triangle& t = m.face(f);
        sum += dot(m.position(t[0]), cross(m.position(t[1]), m.position(t[2]))) / 6;
      }
    return sum;
  };
  const double before = volume(cm);
  auto change = [&](double volume_weight) {
    EnergyOptions options;
    options.star_planes_weight = 0;
    options.volume_weight = volume_weight;
    EnergyPriority energy({}, options);
    energy.initialize(cm);
    double sum = 0;
    int collapses = 0;
    std::vector<VertexId> around;
    for (VertexId a = 0; a < 60; ++a) {
      cm.neighbors(a, around);
      for (VertexId b : around) {
        if (b < a) continue;
        CollapseCandidate c;
        if (!energy.evaluate(cm, a, b, c, Costing::kPerform)) continue;
        CollapseMesh after = cm;
        after.collapse(c.vs, c.vt, c.position, after.edge_faces(c.vs, c.vt));
        sum += std::abs(volume(after) - before);
        ++collapses;
      }
    }
    EXPECT_GT(collapses, 100);
    return sum;
  };
  const double free_change = change(0), kept_change = change(1e6);
  EXPECT_GT(free_change, 1e-4 * before) << "the points and springs alone lose volume";
  EXPECT_LT(kept_change, 1e-3 * free_change);
}

}  // namespace
}  // namespace parapm

namespace parapm {
namespace {

TEST(SharpCurves, BoundariesAndCreasesAboveTheAngle) {
  const Mesh mesh = roof();
  const CollapseMesh cm(mesh);
  // The roof's ridge turns by 2 atan(1/2) = 53 degrees: a crease at 45, not at 60.
  EXPECT_EQ(find_sharp_edges(cm, {}).size(), 16u) << "the 16 boundary edges";
  SharpEdgeOptions options;
  options.crease_angle_degrees = 45;
  EXPECT_EQ(find_sharp_edges(cm, options).size(), 20u) << "and the 4 ridge edges";
  options.boundaries = false;
  EXPECT_EQ(find_sharp_edges(cm, options).size(), 4u);
}

TEST(SharpCurves, ShortCreasesAreNoiseUnlessLong) {
  const Mesh mesh = roof();
  const CollapseMesh cm(mesh);
  SharpEdgeOptions options;
  options.crease_angle_degrees = 45;
  // The ridge is one crease of 4 edges: fewer than 8, but 4 long in a diagonal of 5.8.
  EXPECT_EQ(find_sharp_edges(cm, options).size(), 20u);
  options.long_crease_diagonals = 1;  // now short as well: noise; the boundary stays
  EXPECT_EQ(find_sharp_edges(cm, options).size(), 16u);
  options.min_crease_edges = 4;  // enough edges
  EXPECT_EQ(find_sharp_edges(cm, options).size(), 20u);
  options.min_crease_edges = 5;
  EXPECT_EQ(find_sharp_edges(cm, options).size(), 16u);
  options.min_crease_edges = 1;  // every crease
  EXPECT_EQ(find_sharp_edges(cm, options).size(), 20u);
}

// The rim of a double-sided disc (each face and its reverse; the repair keeps the two sides
// apart inside and joined along the rim), whose faces lie back to back, is a border as an open
// boundary is: kept whatever its length (not a crease of 6 edges, short, taken for noise) and
// whatever the crease angle.
TEST(SharpCurves, TheRimOfADoubleSidedSheetIsABorder) {
  const RepairedMesh repaired = repair_mesh(testing::double_sided(testing::disc(2, 6)));
  const CollapseMesh cm(repaired.mesh);
  SharpEdgeOptions options;
  options.long_crease_diagonals = 1;  // the rim is short: a crease of it would be noise
  options.crease_angle_degrees = 180;
  const auto edges = find_sharp_edges(cm, options);
  ASSERT_EQ(edges.size(), 6u);
  for (const auto& [a, b] : edges) {
    EXPECT_NEAR(length(cm.position(a)), 1.0, kTight) << "a rim vertex";
    EXPECT_NEAR(length(cm.position(b)), 1.0, kTight) << "a rim vertex";
  }
  options.boundaries = false;
  EXPECT_TRUE(find_sharp_edges(cm, options).empty());
}

TEST(SharpCurves, TopologyChangesAreFlagged) {
  const Mesh mesh = roof();
  const CollapseMesh cm(mesh);
  SharpCurves curves;
  SharpEdgeOptions options;
  options.crease_angle_degrees = 45;
  curves.initialize(cm, options);
  auto id = [](int x, int y) { return VertexId((y + 2) * 5 + (x + 2)); };
  EXPECT_EQ(curves.sample_count(), 16u + 3u + 20u) << "curve vertices, then edge midpoints";
  EXPECT_FALSE(curves.changes_topology(id(0, 0), id(1, 0))) << "along the ridge";
  EXPECT_FALSE(curves.changes_topology(id(0, 0), id(0, 1))) << "one end off the curves";
  EXPECT_FALSE(curves.changes_topology(id(-2, 0), id(-1, 0))) << "a corner and the ridge";
  EXPECT_TRUE(curves.changes_topology(id(-2, -1), id(-1, 0)))
      << "a boundary vertex and a ridge vertex joined by a smooth edge: the curves would touch";
}

TEST(SharpCurves, SamplesFollowTheCurveThroughCollapses) {
  // Down to 16 faces the curves (the boundary and the ridge, all straight between corners)
  // stay where they were: every sample stays on a sharp edge, within the springs' pull
  // (kappa 1e-2 with so few points: under 1% of the roof's diagonal).
  const Mesh mesh = roof();
  CollapseMesh cm(mesh);
  EnergyOptions options;
  options.sharp.crease_angle_degrees = 45;
  EnergyPriority energy({}, options);
  Simplifier simplifier(cm, energy, standard_constraints({}));
  simplifier.run({16}, {}, nullptr);
  const SharpCurves& curves = energy.curves();
  for (size_t i = 0; i < curves.sample_count(); ++i) {
    const auto [u, w] = curves.sample_edge(i);
    ASSERT_TRUE(cm.vertex_alive(u)) << "sample " << i;
    ASSERT_TRUE(w == kNoId || curves.is_sharp(u, w)) << "sample " << i;
    EXPECT_LT(std::sqrt(curves.sample_distance_sq(i)), 0.01 * std::sqrt(32.0)) << "sample " << i;
  }
}

}  // namespace
}  // namespace parapm
