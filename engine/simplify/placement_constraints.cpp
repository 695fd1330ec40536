#include "simplify/placement_constraints.h"

#include <algorithm>
#include <cmath>

#include "simplify/vec_math.h"

namespace parapm {

namespace {

// A unit vector perpendicular to the unit vector n.
Vec3 perpendicular(const Vec3& n) {
  Vec3 w = std::fabs(n[0]) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  w = sub(w, scale(n, dot(w, n)));
  return scale(w, 1 / length(w));
}

}  // namespace

void PlacementConstraints::require_cross(const Vec3& e1, const Vec3& e2) {
  // (v - origin).(e1 x w) = e2.w for two directions w across e1.
  const Vec3 along = scale(e1, 1 / length(e1));
  const Vec3 w1 = perpendicular(along);
  for (const Vec3& w : {w1, cross(along, w1)}) require(cross(e1, w), dot(e2, w));
}

void PlacementConstraints::require(Vec3 n, double d) {
  if (count_ == 3) return;
  const double before = length(n);
  if (!(before > 0)) return;
  for (int j = 0; j < count_; ++j) {
    const double along = dot(n, rows_[j]);
    n = sub(n, scale(rows_[j], along));
    d -= along * rhs_[j];
  }
  const double after = length(n);
  if (!(after > std::sin(M_PI / 180) * before)) return;
  rows_[count_] = scale(n, 1 / after);
  rhs_[count_] = d / after;
  ++count_;
}

bool PlacementConstraints::minimize(const Quadric& q, Vec3& out) const {
  if (count_ == 0) return false;
  // The point of the rows' solutions nearest the origin, then along their null space.
  Vec3 v0 = origin_;
  for (int j = 0; j < count_; ++j) v0 = add(v0, scale(rows_[j], rhs_[j]));
  if (count_ == 3) {
    out = v0;
    return std::isfinite(out[0]) && std::isfinite(out[1]) && std::isfinite(out[2]);
  }
  auto times_a = [&](const Vec3& x) {
    return Vec3{q.a00 * x[0] + q.a01 * x[1] + q.a02 * x[2],
                q.a01 * x[0] + q.a11 * x[1] + q.a12 * x[2],
                q.a02 * x[0] + q.a12 * x[1] + q.a22 * x[2]};
  };
  const Vec3 gradient = add(times_a(v0), Vec3{q.b0, q.b1, q.b2});  // half Q's, at v0
  const double trace = q.a00 + q.a11 + q.a22;
  if (count_ == 2) {
    const Vec3 z = cross(rows_[0], rows_[1]);
    const double zaz = dot(z, times_a(z));
    if (!(zaz > 1e-9 * trace)) return false;
    out = add(v0, scale(z, -dot(z, gradient) / zaz));
  } else {
    const Vec3 z1 = perpendicular(rows_[0]);
    const Vec3 z2 = cross(rows_[0], z1);
    const Vec3 a1 = times_a(z1), a2 = times_a(z2);
    const double m00 = dot(z1, a1), m01 = dot(z1, a2), m11 = dot(z2, a2);
    const double det = m00 * m11 - m01 * m01;
    if (!(det > 1e-9 * trace * trace)) return false;
    const double r0 = -dot(z1, gradient), r1 = -dot(z2, gradient);
    const double y0 = (m11 * r0 - m01 * r1) / det, y1 = (m00 * r1 - m01 * r0) / det;
    out = add(v0, add(scale(z1, y0), scale(z2, y1)));
  }
  return std::isfinite(out[0]) && std::isfinite(out[1]) && std::isfinite(out[2]);
}

namespace {

// An end with this many faces has its star summed apart from the other end's, and kept.
constexpr size_t kManyFaces = 16;
constexpr size_t kKeptStars = 1024;  // slots of StarTermsScratch::kept

using VertexStar = StarTermsScratch::VertexStar;

// Fills scratch.order with scratch.faces's terms by p1, then p2 (then the rest, for faces
// alike in both): the order of the positions, whatever the ids and face lists.
void order_by_position(StarTermsScratch& scratch) {
  const auto& terms = scratch.faces;
  auto& order = scratch.order;
  order.resize(terms.size());
  for (uint32_t i = 0; i < terms.size(); ++i) order[i] = {terms[i].p1[0], i};
  std::sort(order.begin(), order.end(), [&](const auto& x, const auto& y) {
    if (x.first != y.first) return x.first < y.first;
    const StarTermsScratch::FaceTerm &s = terms[x.second], &t = terms[y.second];
    if (s.p1 != t.p1) return s.p1 < t.p1;
    if (s.p2 != t.p2) return s.p2 < t.p2;
    if (s.end != t.end) return s.end < t.end;
    return s.vanishes < t.vanishes;
  });
}

// Adds to `planes` the plane through `corner` of a face whose normal is n (twice its area),
// weighted by its area; nothing for a face without area.
void add_face_plane(const Vec3& n, const Vec3& corner, Quadric& planes) {
  const double twice_area = length(n);
  if (!(twice_area > 0)) return;
  const Vec3 unit = scale(n, 1 / twice_area);
  planes += Quadric::from_plane(unit, -dot(unit, corner), 0.5 * twice_area);
}

// Adds face (end, p1, p2)'s terms to `sums`.
void add_face(const Vec3& end, const Vec3& p1, const Vec3& p2, bool planes, VertexStar& sums) {
  const Vec3 c = cross(sub(p1, end), sub(p2, end));
  sums.cross = add(sums.cross, c);
  sums.turn = add(sums.turn, sub(p2, p1));
  if (planes) add_face_plane(c, end, sums.planes);
}

// The sums over every face around v, in the order of their corners' positions.
VertexStar sum_vertex_star(const CollapseMesh& mesh, VertexId v, bool planes,
                           StarTermsScratch& scratch) {
  auto& terms = scratch.faces;
  terms.clear();
  const Vec3& end = mesh.position(v);
  for (const FaceId f : mesh.faces_of(v)) {
    const Triangle& t = mesh.face(f);
    const int k = corner_of(t, v);
    terms.push_back({mesh.position(t[(k + 1) % 3]), mesh.position(t[(k + 2) % 3]), end, false});
  }
  order_by_position(scratch);
  VertexStar sums;
  for (const auto& [first, i] : scratch.order)
    add_face(end, terms[i].p1, terms[i].p2, planes, sums);
  return sums;
}

// sum_vertex_star's, from the scratch's kept sums while v's star version holds.
VertexStar vertex_star(const CollapseMesh& mesh, VertexId v, bool planes,
                       StarTermsScratch& scratch) {
  if (mesh.faces_of(v).size() < kManyFaces) return sum_vertex_star(mesh, v, planes, scratch);
  if (scratch.kept.empty()) scratch.kept.resize(kKeptStars);
  StarTermsScratch::KeptStar& slot = scratch.kept[v % kKeptStars];
  if (slot.mesh != mesh.identity() || slot.v != v || slot.version != mesh.star_version(v) ||
      (planes && !slot.planes))
    slot = {mesh.identity(), v, mesh.star_version(v), planes,
            sum_vertex_star(mesh, v, planes, scratch)};
  return slot.sums;
}

// An edge's sums from its end `end`: end's star's less the edge's faces, with g and h taken
// about `origin`. Each side depends on its own end's star alone, so a + b sums as b + a.
void add_side(const CollapseMesh& mesh, VertexId end, const EdgeFaces& edge, const Vec3& origin,
              bool with_planes, StarTermsScratch& scratch, Vec3& g, double& h, Quadric& planes) {
  VertexStar sums = vertex_star(mesh, end, with_planes, scratch);
  VertexStar gone;  // (at most two faces: their sum is the same in either order)
  const Vec3& p = mesh.position(end);
  for (const FaceId f : {edge.left, edge.right}) {
    if (f == kNoId) continue;
    const Triangle& t = mesh.face(f);
    const int k = corner_of(t, end);
    add_face(p, mesh.position(t[(k + 1) % 3]), mesh.position(t[(k + 2) % 3]), with_planes, gone);
  }
  sums.cross = sub(sums.cross, gone.cross);
  sums.turn = sub(sums.turn, gone.turn);
  sums.planes -= gone.planes;
  // With d = end - origin, a face's (p1 - origin) x (p2 - origin) is (p1 - end) x (p2 - end)
  // + d x (p2 - p1), and d . that is d . ((p1 - end) x (p2 - end)).
  const Vec3 d = sub(p, origin);
  g = add(sums.cross, cross(d, sums.turn));
  h = dot(d, sums.cross);
  planes = sums.planes;
}

}  // namespace

void star_volume(const CollapseMesh& mesh, VertexId a, VertexId b, const Vec3& origin,
                 StarTermsScratch& scratch, Vec3& g, double& h, Quadric* planes) {
  if (std::max(mesh.faces_of(a).size(), mesh.faces_of(b).size()) >= kManyFaces) {
    // A face holding both ends adds nothing to h (origin lies on the edge) and vanishes.
    Vec3 ga, gb;
    double ha, hb;
    Quadric qa, qb;
    const EdgeFaces edge = mesh.edge_faces(a, b);
    add_side(mesh, a, edge, origin, planes != nullptr, scratch, ga, ha, qa);
    add_side(mesh, b, edge, origin, planes != nullptr, scratch, gb, hb, qb);
    g = add(ga, gb);
    h = ha + hb;
    if (planes) {
      qa += qb;
      *planes += qa;
    }
    return;
  }
  // A face holding both ends is summed once, from the end whose position comes first.
  auto& terms = scratch.faces;
  terms.clear();
  for (const VertexId end : {a, b}) {
    const VertexId other = end == a ? b : a;
    for (const FaceId f : mesh.faces_of(end)) {
      const Triangle& t = mesh.face(f);
      const bool vanishes = t[0] == other || t[1] == other || t[2] == other;
      if (vanishes && mesh.position(other) < mesh.position(end)) continue;
      if (vanishes && !(mesh.position(end) < mesh.position(other)) && end == b) continue;
      const int k = corner_of(t, end);
      terms.push_back({mesh.position(t[(k + 1) % 3]), mesh.position(t[(k + 2) % 3]),
                       mesh.position(end), vanishes});
    }
  }
  order_by_position(scratch);
  g = {0, 0, 0};
  h = 0;
  for (const auto& [first, i] : scratch.order) {
    const StarTermsScratch::FaceTerm& term = terms[i];
    const Vec3 c = cross(sub(term.p1, origin), sub(term.p2, origin));
    h += dot(sub(term.end, origin), c);
    if (term.vanishes) continue;
    g = add(g, c);
    if (planes)
      add_face_plane(cross(sub(term.p1, term.end), sub(term.p2, term.end)), term.end, *planes);
  }
}

bool star_border(const CollapseMesh& mesh, VertexId a, VertexId b, const Vec3& origin,
                 StarTermsScratch& scratch, Vec3& e1, Vec3& e2) {
  // The border edges at an end, directed as their faces hold them: (end, next) where no face
  // holds (next, end), and (previous, end) where none holds (end, previous). One between a and
  // b is listed from a.
  auto& border = scratch.border;
  border.clear();
  for (const VertexId end : {a, b}) {
    if (!mesh.is_boundary(end)) continue;
    // A face holding the reverse of a half-edge at end holds end too: the faces around end,
    // as (next, previous), tell which of their half-edges lie on the border.
    auto& fan = scratch.fan;
    fan.clear();
    for (const FaceId f : mesh.faces_of(end)) {
      const Triangle& t = mesh.face(f);
      const int k = corner_of(t, end);
      fan.push_back({t[(k + 1) % 3], t[(k + 2) % 3]});
    }
    auto held = [&](VertexId from, VertexId to) {  // some face around end holds from -> to
      for (const auto& [next, previous] : fan)
        if ((from == end && to == next) || (to == end && from == previous)) return true;
      return false;
    };
    for (const auto& [next, previous] : fan) {
      for (const auto& [from, to] : {std::pair{end, next}, std::pair{previous, end}}) {
        const VertexId far = from == end ? to : from;
        if (end == b && far == a) continue;
        if (mesh.is_boundary(far) && !held(to, from)) border.push_back({from, to});
      }
    }
  }
  if (border.empty()) return false;
  std::sort(border.begin(), border.end(), [&](const auto& x, const auto& y) {
    const Vec3 &x0 = mesh.position(x.first), &y0 = mesh.position(y.first);
    return x0 != y0 ? x0 < y0 : mesh.position(x.second) < mesh.position(y.second);
  });
  e1 = {0, 0, 0};
  e2 = {0, 0, 0};
  for (const auto& [p, q] : border) {
    const Vec3 from = sub(mesh.position(p), origin), to = sub(mesh.position(q), origin);
    e2 = add(e2, cross(from, to));
    const bool p_moves = p == a || p == b, q_moves = q == a || q == b;
    if (p_moves && !q_moves) e1 = add(e1, to);
    if (q_moves && !p_moves) e1 = sub(e1, from);
  }
  return true;
}

}  // namespace parapm
