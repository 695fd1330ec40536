// The quadric's star sums (placement_constraints.h): the volume equation and the star's planes
// of an edge, summed face by face for small stars and from each end's kept sums for an end of
// many faces, and the star versions that keep those sums current.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "drawn_meshes.h"
#include "simplify/collapse_mesh.h"
#include "simplify/placement_constraints.h"
#include "simplify/quadric.h"
#include "simplify/vec_math.h"

namespace parapm {
namespace {

struct StarSums {
  Vec3 g{};
  double h = 0;
  Quadric planes;
};

StarSums summed(const CollapseMesh& mesh, VertexId a, VertexId b, StarTermsScratch& scratch) {
  StarSums s;
  const Vec3 origin = scale(add(mesh.position(a), mesh.position(b)), 0.5);
  star_volume(mesh, a, b, origin, scratch, s.g, s.h, &s.planes);
  return s;
}

// The same sums straight from their definition: every face around a or b once, the faces
// holding both counted in h only.
StarSums by_definition(const CollapseMesh& mesh, VertexId a, VertexId b) {
  StarSums s;
  const Vec3 origin = scale(add(mesh.position(a), mesh.position(b)), 0.5);
  std::set<FaceId> star(mesh.faces_of(a).begin(), mesh.faces_of(a).end());
  star.insert(mesh.faces_of(b).begin(), mesh.faces_of(b).end());
  for (FaceId f : star) {
    const Triangle& t = mesh.face(f);
    const VertexId end = corner_of(t, a) >= 0 ? a : b;
    const int k = corner_of(t, end);
    const Vec3 &p = mesh.position(end), &p1 = mesh.position(t[(k + 1) % 3]),
               &p2 = mesh.position(t[(k + 2) % 3]);
    const Vec3 c = cross(sub(p1, origin), sub(p2, origin));
    s.h += dot(sub(p, origin), c);
    if (corner_of(t, a) >= 0 && corner_of(t, b) >= 0) continue;
    s.g = add(s.g, c);
    const Vec3 n = cross(sub(p1, p), sub(p2, p));
    const Vec3 unit = scale(n, 1 / length(n));
    s.planes += Quadric::from_plane(unit, -dot(unit, p), 0.5 * length(n));
  }
  return s;
}

void expect_near(const StarSums& x, const StarSums& y, const char* what) {
  const double tolerance = 1e-12;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(x.g[i], y.g[i], tolerance) << what;
  EXPECT_NEAR(x.h, y.h, tolerance) << what;
  const Quadric &p = x.planes, &q = y.planes;
  for (const auto& [u, v] : {std::pair{p.a00, q.a00},
                             {p.a01, q.a01},
                             {p.a02, q.a02},
                             {p.a11, q.a11},
                             {p.a12, q.a12},
                             {p.a22, q.a22},
                             {p.b0, q.b0},
                             {p.b1, q.b1},
                             {p.b2, q.b2},
                             {p.c, q.c},
                             {p.weight, q.weight}})
    EXPECT_NEAR(u, v, tolerance) << what;
}

bool same_bits(const StarSums& x, const StarSums& y) {
  return std::memcmp(&x.g, &y.g, sizeof x.g) == 0 && std::memcmp(&x.h, &y.h, sizeof x.h) == 0 &&
         std::memcmp(&x.planes, &y.planes, sizeof x.planes) == 0;
}

// A rippled sphere whose poles hold 40 faces each: their edges take the kept sums.
Mesh sphere_with_hubs() { return testing::uv_sphere(8, 40, 0.2); }
constexpr VertexId kNorth = 0;
constexpr VertexId ring_vertex(int s) { return VertexId(1 + s); }  // on the first ring

TEST(StarSums, AnEdgeAtAHubSumsItsStarFaceByFace) {
  const CollapseMesh mesh(sphere_with_hubs());
  ASSERT_EQ(mesh.faces_of(kNorth).size(), 40u);
  StarTermsScratch scratch;
  for (int s : {0, 7, 23}) {
    const VertexId v = ring_vertex(s);
    expect_near(summed(mesh, kNorth, v, scratch), by_definition(mesh, kNorth, v), "hub edge");
    // (again, from the kept sums, and from the other end: the same bits)
    const StarSums first = summed(mesh, kNorth, v, scratch);
    EXPECT_TRUE(same_bits(summed(mesh, v, kNorth, scratch), first));
    EXPECT_TRUE(same_bits(summed(mesh, kNorth, v, scratch), first));
  }
  const VertexId a = ring_vertex(3), b = VertexId(1 + 40 + 3);  // to the second ring: small stars
  expect_near(summed(mesh, a, b, scratch), by_definition(mesh, a, b), "small star");
}

// Collapses beside the hub change its star: its kept sums follow, on the mesh and on a copy
// that went another way (the hub's star version there the same number).
TEST(StarSums, AHubsKeptSumsFollowItsCollapses) {
  CollapseMesh mesh(sphere_with_hubs());
  StarTermsScratch scratch;
  const VertexId probe = ring_vertex(20);
  summed(mesh, kNorth, probe, scratch);  // kept
  CollapseMesh other = mesh;
  const uint32_t south_version = mesh.star_version(VertexId(mesh.vertex_capacity() - 1));
  const uint32_t hub_version = mesh.star_version(kNorth);
  const VertexId vs = ring_vertex(5), vt = ring_vertex(6);
  mesh.collapse(vs, vt, {0.3, 0.3, 0.9}, mesh.edge_faces(vs, vt));
  EXPECT_NE(mesh.star_version(kNorth), hub_version);
  EXPECT_EQ(mesh.star_version(VertexId(mesh.vertex_capacity() - 1)), south_version);
  expect_near(summed(mesh, kNorth, probe, scratch), by_definition(mesh, kNorth, probe),
              "after a collapse on the hub's ring");

  const VertexId ws = ring_vertex(30), wt = ring_vertex(31);
  other.collapse(ws, wt, {-0.2, -0.4, 0.8}, other.edge_faces(ws, wt));
  ASSERT_EQ(other.star_version(kNorth), mesh.star_version(kNorth));
  expect_near(summed(other, kNorth, probe, scratch), by_definition(other, kNorth, probe),
              "on the copy");
  expect_near(summed(mesh, kNorth, probe, scratch), by_definition(mesh, kNorth, probe),
              "back on the mesh");
}

// A subset job numbers the vertices and lists the faces its own way: the sums' bits stay.
TEST(StarSums, TheBitsDoNotDependOnIdsOrFaceOrder) {
  const Mesh input = sphere_with_hubs();
  std::vector<VertexId> renamed(input.positions.size());
  std::iota(renamed.begin(), renamed.end(), 0);
  std::mt19937 random(7);
  std::shuffle(renamed.begin(), renamed.end(), random);
  Mesh shuffled;
  shuffled.positions.resize(input.positions.size());
  for (VertexId v = 0; v < input.positions.size(); ++v)
    shuffled.positions[renamed[v]] = input.positions[v];
  for (const Triangle& t : input.faces)  // each face's corners rotated by one
    shuffled.faces.push_back({renamed[t[1]], renamed[t[2]], renamed[t[0]]});
  std::shuffle(shuffled.faces.begin(), shuffled.faces.end(), random);
  const CollapseMesh mesh(input), other(shuffled);
  StarTermsScratch scratch, other_scratch;
  for (const auto& [a, b] : {std::pair{kNorth, ring_vertex(4)},
                             {ring_vertex(9), ring_vertex(10)},
                             {ring_vertex(12), VertexId(1 + 40 + 12)}})
    EXPECT_TRUE(same_bits(summed(mesh, a, b, scratch),
                          summed(other, renamed[a], renamed[b], other_scratch)))
        << a << " " << b;
}

}  // namespace
}  // namespace parapm
