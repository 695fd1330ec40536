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

// The border equations (star_border) against their definition: every half-edge of a live face
// without a twin, with an end at a or b, once; e2 sums (p - o) x (q - o) over them, e1 the ends
// that stay on those with one moving end. On a disc and on a sphere with holes cut, as drawn
// and after collapses along the border (each end with one fan: a repaired mesh's).
TEST(StarSums, TheBorderEquationsSumEveryBorderEdgeAtEitherEnd) {
  auto border_by_definition = [](const CollapseMesh& mesh, VertexId a, VertexId b,
                                 const Vec3& origin, Vec3& e1, Vec3& e2) {
    std::set<std::pair<VertexId, VertexId>> held;
    for (FaceId f = 0; f < mesh.face_capacity(); ++f)
      if (mesh.face_alive(f))
        for (int k = 0; k < 3; ++k) held.insert({mesh.face(f)[k], mesh.face(f)[(k + 1) % 3]});
    e1 = e2 = {0, 0, 0};
    bool any = false;
    for (const auto& [p, q] : held) {
      const bool p_moves = p == a || p == b, q_moves = q == a || q == b;
      if ((!p_moves && !q_moves) || held.count({q, p})) continue;
      any = true;
      const Vec3 from = sub(mesh.position(p), origin), to = sub(mesh.position(q), origin);
      e2 = add(e2, cross(from, to));
      if (p_moves && !q_moves) e1 = add(e1, to);
      if (q_moves && !p_moves) e1 = sub(e1, from);
    }
    return any;
  };
  // (holes apart: a vertex on two, a bowtie, is the repair's to split)
  Mesh holed = testing::uv_sphere(10, 24, 0.1);
  std::erase_if(holed.faces, [](const Triangle& t) {
    return std::find(t.begin(), t.end(), VertexId(1 + 2 * 24 + 3)) != t.end() ||
           std::find(t.begin(), t.end(), VertexId(1 + 6 * 24 + 15)) != t.end();
  });
  for (const Mesh& drawn : {testing::disc(4, 16), holed}) {
    CollapseMesh mesh(drawn);
    StarTermsScratch scratch;
    auto check_every_edge = [&](const char* when) {
      int checked = 0;
      for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
        if (!mesh.face_alive(f)) continue;
        for (int k = 0; k < 3; ++k) {
          const VertexId a = mesh.face(f)[k], b = mesh.face(f)[(k + 1) % 3];
          const Vec3 origin = scale(add(mesh.position(a), mesh.position(b)), 0.5);
          Vec3 e1, e2, want_e1, want_e2;
          const bool found = star_border(mesh, a, b, origin, scratch, e1, e2);
          ASSERT_EQ(found, border_by_definition(mesh, a, b, origin, want_e1, want_e2))
              << when << ": " << a << " " << b;
          if (!found) continue;
          ++checked;
          for (int i = 0; i < 3; ++i) {
            EXPECT_NEAR(e1[i], want_e1[i], 1e-12) << when << ": " << a << " " << b;
            EXPECT_NEAR(e2[i], want_e2[i], 1e-12) << when << ": " << a << " " << b;
          }
        }
      }
      EXPECT_GT(checked, 20) << when;
    };
    check_every_edge("as drawn");
    // Border edges collapsed (b into a, where a is), those whose ends share their apex only
    // (the link condition: each vertex keeps one fan).
    int collapsed = 0;
    for (FaceId f = 0; f < mesh.face_capacity() && collapsed < 6; ++f) {
      for (int k = 0; k < 3 && mesh.face_alive(f); ++k) {
        const VertexId a = mesh.face(f)[k], b = mesh.face(f)[(k + 1) % 3];
        const EdgeFaces edge = mesh.edge_faces(a, b);
        int common = 0;
        mesh.for_each_common_neighbor(a, b, [&](VertexId) { ++common; });
        if (edge.right != kNoId || common != 1) continue;  // not a border edge, or not legal
        mesh.collapse(a, b, mesh.position(a), edge);
        ++collapsed;
      }
    }
    ASSERT_GT(collapsed, 0);
    check_every_edge("after border collapses");
  }
}

}  // namespace
}  // namespace parapm
