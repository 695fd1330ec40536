// The test PMs of pm_fixtures.h. Hand-made ones first, each with its drawing; then the random
// generator, which drives a PmCursor and writes each split from the current mesh so that the
// split is valid by construction.
#include "pm_fixtures.h"

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include "pm/pm_cursor.h"

namespace parapm::testing {

namespace {

VertexSplit make_split(VertexId vs, VertexId vl, VertexId vr, float error, Vec3 before, Vec3 after,
                       Vec3 vt) {
  VertexSplit s;
  s.vs = vs;
  s.vl = vl;
  s.vr = vr;
  s.error = error;
  s.vs_before = before;
  s.vs_after = after;
  s.vt_after = vt;
  return s;
}

}  // namespace

// Full resolution (level 2), y up:      Base mesh (level 0):
//
//   6-----------4                                   4
//   |  \       /|                                  /|
//   |    \   /  |                    2  .        /  |
//   2-----3     |                    |    .   /     |
//   | \   | \   |                    |      3       |
//   |  \  |  \  |                    |  \   |  \    |
//   0-----1-----5                    0-------1      (1 at x = 1.5)
//
// Base faces: 0 (0,1,2), 1 (1,3,2), 2 (1,4,3), 3 (3,4,2); vertex 2 at (0, 1.5).
// Split 0 (vt = 5): vs 1, vl 3, no vr: fl = (1,5,3) becomes face 4; the fan is the clockwise
//   walk from the face holding 3->1, face 2, which becomes (5,4,3).
// Split 1 (vt = 6): vs 2, no vl, vr 3: fr = (6,2,3) becomes face 5; the fan is the
//   counter-clockwise walk from the face holding 2->3, face 3, which becomes (3,4,6).
ProgressiveMesh strip_pm() {
  ProgressiveMesh pm;
  pm.base.positions = {{0, 0, 0}, {1.5, 0, 0}, {0, 1.5, 0}, {1, 1, 0}, {2, 2, 0}};
  pm.base.faces = {{0, 1, 2}, {1, 3, 2}, {1, 4, 3}, {3, 4, 2}};
  pm.base.positions_are_float = true;
  pm.splits.push_back(make_split(1, 3, kNoId, 0.5f, {1.5, 0, 0}, {1, 0, 0}, {2, 0, 0}));
  pm.splits.push_back(make_split(2, kNoId, 3, 0.25f, {0, 1.5, 0}, {0, 1, 0}, {0, 2, 0}));
  pm.info.metric = "hand";
  return pm;
}

std::vector<Triangle> strip_full_faces() {
  return {{0, 1, 2}, {1, 3, 2}, {5, 4, 3}, {3, 4, 6}, {1, 5, 3}, {6, 2, 3}};
}

// Octahedron: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z; faces counter-clockwise seen from outside.
// Seen from +z, before and after split 0 (vs 4, vr 0, vl 1; vt = 6):
//
//        2                  2          The fan turns counter-clockwise around 4 from the
//      / | \              / | \        face holding 4->0, (0,2,4), to the face holding
//    1 - 4 - 0          1 - 6 - 0      1->4, (2,1,4); both move to 6: (0,2,6), (2,1,6).
//      \ | /            | \ | / |      The new faces are fl = (4,6,1) and fr = (6,4,0).
//        3              |   4   |
//                        \  |  /       (4 moves towards -y, 6 sits towards +y)
//                           3
//
// Split 1: vs 5, vr 2, vl 3 (vt = 7): the fan is (2,0,5), (0,3,5) (the +x side of 5).
// Split 2: vs 6, vr 2, vl 4 (vt = 8): the fan is (2,1,6) and fl of split 0, (4,6,1): a split
//   of a vertex made by an earlier split, whose fan contains a face made by a split.
ProgressiveMesh octahedron_pm(bool attributes) {
  ProgressiveMesh pm;
  pm.base.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  pm.base.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                   {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  pm.base.positions_are_float = true;
  pm.splits.push_back(make_split(4, 1, 0, 3.0f, {0, 0, 1}, {0, -0.25, 1}, {0, 0.25, 1}));
  pm.splits.push_back(make_split(5, 3, 2, 2.0f, {0, 0, -1}, {-0.25, 0, -1}, {0.25, 0, -1}));
  pm.splits.push_back(
      make_split(6, 4, 2, 2.0f, {0, 0.25, 1}, {0.125, 0.375, 1}, {-0.125, 0.375, 1}));
  pm.info.metric = "hand";
  if (!attributes) return pm;

  // Texture coordinates: base wedge v belongs to vertex v, value (v / 8, 1/2).
  pm.base.layout.texcoords = true;
  for (VertexId v = 0; v < 6; ++v) {
    pm.base.wedge_vertex.push_back(v);
    pm.base.wedge_values.insert(pm.base.wedge_values.end(), {float(v) / 8, 0.5f});
  }
  for (const Triangle& t : pm.base.faces) pm.base.face_wedges.push_back(t);
  // Split 0: fl (4,6,1) uses wedges 4, new 6, 1; fr (6,4,0) uses 6 again, new 7 (a seam at
  // vs), 0. Wedge 4 moves from (1/2, 1/2) to (1/2, 5/8).
  VertexSplit& s0 = pm.splits[0];
  s0.corner_wedges = {4, 6, 1, 6, 7, 0};
  s0.new_wedge_count = 2;
  pm.new_wedge_values.insert(pm.new_wedge_values.end(), {0.75f, 0.25f, 0.875f, 0.25f});
  s0.wedge_changes_begin = 0;
  s0.wedge_changes_count = 1;
  pm.wedge_changes.push_back({4, 0});
  pm.wedge_change_values.insert(pm.wedge_change_values.end(), {0.5f, 0.5f, 0.5f, 0.625f});
  // Split 1: fl (5,7,3) uses 5, new 8, 3; fr (7,5,2) uses 8, 5, 2. No change.
  VertexSplit& s1 = pm.splits[1];
  s1.corner_wedges = {5, 8, 3, 8, 5, 2};
  s1.new_wedge_count = 1;
  pm.new_wedge_values.insert(pm.new_wedge_values.end(), {-0.125f, 1.0f});
  s1.wedge_changes_begin = 1;
  // Split 2: fl (6,8,4) uses 6, new 9, 4; fr (8,6,2) uses 9, 6, 2. Wedges 0 and 6 change.
  VertexSplit& s2 = pm.splits[2];
  s2.corner_wedges = {6, 9, 4, 9, 6, 2};
  s2.new_wedge_count = 1;
  pm.new_wedge_values.insert(pm.new_wedge_values.end(), {-0.0f, 0.125f});
  s2.wedge_changes_begin = 1;
  s2.wedge_changes_count = 2;
  pm.wedge_changes.push_back({0, 4});
  pm.wedge_change_values.insert(pm.wedge_change_values.end(), {0.0f, 0.5f, 0.0625f, 0.5f});
  pm.wedge_changes.push_back({6, 8});
  pm.wedge_change_values.insert(pm.wedge_change_values.end(), {0.75f, 0.25f, 0.75f, 0.3125f});
  return pm;
}

// Full resolution:                 Base mesh (B collapsed into S):
//
//     T2 ------ T1                    T2 ------ T1       B is on the boundary, S interior.
//     /  \      / \                   /  \      / \      Collapsing B into S leaves S on
//    /    \    /   \                 /    \    /   \     the boundary with the faces
//   C ----- S ----- A               C ---- S ------ A    (S,R,A), (S,A,T1), (S,T1,T2),
//   | \     |     / |                \   /    \    /     (S,T2,C), (S,C,L).
//   |   \   |   /   |                 \ /       \ /
//   L ----- B ----- R                  L          R
//
// Ids: R 0, A 1, S 2, C 3, L 4, T1 5, T2 6, B 7 (= vt). The split: vs S, vl A, vr C.
// Counter-clockwise from the face holding S->C: (S,C,L), then no face holds S->L: boundary.
// Clockwise from the face holding A->S: (S,R,A), then no face holds R->S: boundary. Both
// move to B.
ProgressiveMesh cut_fan_pm() {
  ProgressiveMesh pm;
  pm.base.positions = {{2, 0, 0},  {1.5, 1, 0}, {0, 0.5, 0}, {-1.5, 1, 0},
                       {-2, 0, 0}, {1, 2, 0},   {-1, 2, 0}};
  pm.base.faces = {{2, 0, 1}, {2, 1, 5}, {2, 5, 6}, {2, 6, 3}, {2, 3, 4}};
  pm.base.positions_are_float = true;
  pm.splits.push_back(make_split(2, 1, 3, 1.0f, {0, 0.5, 0}, {0, 1, 0}, {0, 0, 0}));
  pm.info.metric = "hand";
  return pm;
}

std::vector<Triangle> cut_fan_full_faces() {
  return {{7, 0, 1}, {2, 1, 5}, {2, 5, 6}, {2, 6, 3}, {7, 3, 4}, {2, 7, 1}, {7, 2, 3}};
}

namespace {

// The faces of v in counter-clockwise order, as (v, n[i], n[i + 1]): n has one more entry
// than there are faces when v is on a boundary; for an interior vertex n[d] == n[0].
struct Ring {
  std::vector<VertexId> n;
  bool boundary = false;
};

Ring ring_of(const PmCursor& cursor, VertexId v) {
  std::map<VertexId, VertexId> next;  // a -> b for each face (v, a, b)
  std::set<VertexId> bs;
  for (FaceId f : cursor.faces_of(v)) {
    const Triangle& t = cursor.faces()[f];
    const int k = t[0] == v ? 0 : (t[1] == v ? 1 : 2);
    next[t[(k + 1) % 3]] = t[(k + 2) % 3];
    bs.insert(t[(k + 2) % 3]);
  }
  Ring ring;
  if (next.empty()) return ring;
  VertexId start = next.begin()->first;
  for (const auto& [a, b] : next)
    if (!bs.count(a)) {
      start = a;
      ring.boundary = true;
    }
  ring.n.push_back(start);
  for (size_t i = 0; i < next.size(); ++i) ring.n.push_back(next.at(ring.n.back()));
  return ring;
}

}  // namespace

ProgressiveMesh random_pm(size_t count, const RandomPmOptions& options) {
  std::mt19937_64 rng(options.seed);
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  auto pick = [&](size_t n) { return size_t(rng() % n); };
  auto coordinate = [&](double x) { return options.float32 ? double(float(x)) : x; };

  ProgressiveMesh pm;
  Mesh& base = pm.base;
  if (options.closed) {
    base = octahedron_pm().base;
  } else {
    // A 5 x 5 grid of vertices, two triangles per square.
    const int n = 5;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) base.positions.push_back({coordinate(x + 0.1 * y), double(y), 0});
    for (int y = 0; y + 1 < n; ++y)
      for (int x = 0; x + 1 < n; ++x) {
        const VertexId a = VertexId(y * n + x), b = a + 1, c = a + n, d = c + 1;
        base.faces.push_back({a, b, d});
        base.faces.push_back({a, d, c});
      }
  }
  base.positions_are_float = options.float32;
  auto random_value = [&]() { return pick(16) == 0 ? -0.0f : float(uniform(-2, 2)); };
  if (options.attributes) {
    base.layout.texcoords = true;
    for (VertexId v = 0; v < base.vertex_count(); ++v) {
      base.wedge_vertex.push_back(v);
      base.wedge_values.push_back(random_value());
      base.wedge_values.push_back(random_value());
    }
    base.face_wedges.clear();
    for (const Triangle& t : base.faces) base.face_wedges.push_back(t);
  }
  pm.info.metric = "random";
  pm.splits.reserve(count);

  PmCursor cursor(pm);  // reads pm.splits[level] as each split is appended
  float error = 1000;
  while (pm.splits.size() < count) {
    VertexSplit s;
    s.vs = VertexId(pick(cursor.vertex_count()));
    const Ring ring = ring_of(cursor, s.vs);
    const size_t d = ring.n.size() - 1;  // faces around vs
    if (ring.n.empty() || d == 0) continue;
    if (!ring.boundary) {
      const size_t j = pick(d);
      const size_t k = std::clamp<size_t>(d / 2 + pick(3) - 1, 1, d - 1);
      s.vr = ring.n[j];
      s.vl = ring.n[(j + k) % d];
    } else {
      const size_t j = pick(d + 1), m = pick(d + 1);
      const size_t kind = pick(4);
      if (kind == 0) {
        s.vr = ring.n[j];
      } else if (kind == 1) {
        s.vl = ring.n[m];
      } else {
        if (j == m) continue;
        s.vr = ring.n[j];
        s.vl = ring.n[m];
      }
    }
    if (pick(10) != 0) error = float(error * uniform(0.9, 1.0));
    s.error = error;
    s.vs_before = cursor.positions()[s.vs];
    Vec3 offset;
    for (double& c : offset) c = uniform(-0.1, 0.1);
    for (int k = 0; k < 3; ++k) {
      s.vs_after[k] = coordinate(s.vs_before[k] - offset[k]);
      s.vt_after[k] = coordinate(s.vs_before[k] + offset[k]);
    }
    if (options.attributes) {
      const WedgeId existing = WedgeId(cursor.wedge_count());
      WedgeId next_new = existing;
      auto old_wedge = [&]() { return WedgeId(pick(existing)); };
      auto new_wedge = [&]() {
        for (int k = 0; k < 2; ++k) pm.new_wedge_values.push_back(random_value());
        ++s.new_wedge_count;
        return next_new++;
      };
      if (s.has_fl()) {
        s.corner_wedges[0] = old_wedge();
        s.corner_wedges[1] = new_wedge();
        s.corner_wedges[2] = old_wedge();
      }
      if (s.has_fr()) {
        s.corner_wedges[3] = next_new > existing && pick(2) ? next_new - 1 : new_wedge();
        s.corner_wedges[4] = pick(4) == 0 ? new_wedge() : old_wedge();
        s.corner_wedges[5] = old_wedge();
      }
      s.wedge_changes_begin = uint32_t(pm.wedge_changes.size());
      if (pick(3) == 0) {
        std::set<WedgeId> changed;
        const size_t changes = 1 + pick(2);
        for (size_t c = 0; c < changes; ++c) changed.insert(old_wedge());
        for (WedgeId w : changed) {
          pm.wedge_changes.push_back({w, uint32_t(pm.wedge_change_values.size())});
          for (int k = 0; k < 2; ++k)
            pm.wedge_change_values.push_back(cursor.wedge_values()[w * 2 + k]);
          for (int k = 0; k < 2; ++k) pm.wedge_change_values.push_back(random_value());
        }
        s.wedge_changes_count = uint32_t(changed.size());
      }
    }
    pm.splits.push_back(s);
    cursor.apply_next();
  }
  return pm;
}

bool is_oriented_manifold(const std::vector<Triangle>& faces) {
  std::set<std::pair<VertexId, VertexId>> edges;
  for (const Triangle& t : faces) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) return false;
    for (int k = 0; k < 3; ++k)
      if (!edges.insert({t[k], t[(k + 1) % 3]}).second) return false;
  }
  return true;
}

std::vector<Triangle> canonical_faces(std::vector<Triangle> faces) {
  for (Triangle& t : faces) std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  std::sort(faces.begin(), faces.end());
  return faces;
}

}  // namespace parapm::testing
