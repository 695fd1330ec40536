#include "simplify/energy_priority.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <span>

#include <Eigen/Dense>

#include "simplify/face_fold.h"
#include "simplify/point_projection.h"
#include "simplify/sample_thinning.h"
#include "simplify/surface_samples.h"
#include "simplify/vec_math.h"
#include "util/error.h"

namespace parapm {
namespace {

// Whether triangle (q0, q1, q2), of normal n (|n|^2 = n_sq), is wide enough to have a plane:
// a thinner one is measured exactly, point by point.
bool has_plane(double n_sq, const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  const Vec3 e1 = sub(q1, q0), e2 = sub(q2, q0);
  return n_sq > 1e-12 * dot(e1, e1) * dot(e2, e2) && n_sq > 0;
}

Vec3 rounded(Vec3 v, bool to_float) {
  if (to_float)
    for (double& c : v) c = round_to_float(c);
  return v;
}

}  // namespace

double EnergyPriority::topology_price(double diagonal) {
  const double moved = EnergyPriority::kTopologyPrice * diagonal;
  return moved * moved;
}

double spring_constant(double points_per_face) {
  if (points_per_face < 4) return 1e-2;
  if (points_per_face < 8) return 1e-4;
  return 1e-8;
}

void EnergyPriority::initialize(const CollapseMesh& mesh) {
  for (const std::function<void()>& part : initialization_parts(mesh)) part();
}

std::vector<std::function<void()>> EnergyPriority::initialization_parts(const CollapseMesh& mesh) {
  return {[this, &mesh] { initialize_curves(mesh); }, [this, &mesh] { initialize_points(mesh); }};
}

void EnergyPriority::initialize_curves(const CollapseMesh& mesh) {
  if (options_.discontinuities) {
    curves_.initialize(mesh, options_.sharp);
  } else {
    curves_ = SharpCurves{};
    curves_.initialize_empty(mesh);
  }
}

void EnergyPriority::reset_point_lists(const CollapseMesh& mesh) {
  face_points_.assign(mesh.face_capacity(), {});
  moments_.assign(mesh.face_capacity(), PointMoments{});
  moments_ready_.assign(mesh.face_capacity(), 0);
  own_.assign(mesh.face_capacity(), OwnError{});
  max_distance_sq_.assign(mesh.face_capacity(), 0);
  drift_.assign(mesh.face_capacity(), 0);
  parked_point_.assign(mesh.vertex_capacity(), kNoPoint);
}

void EnergyPriority::initialize_points(const CollapseMesh& mesh) {
  const std::vector<SurfaceSample> samples =
      sample_surface(mesh, options_.samples_per_face, options_.seed);
  const double diagonal = diagonal_of(mesh);
  topology_price_ = topology_price(diagonal);

  const bool scalar = mesh.has_wedges() && attributes_.layout.any();
  scalar_.initialize(scalar ? attributes_.layout : AttributeLayout{}, attributes_.values,
                     options_.attribute_weight * diagonal);

  point_id_.clear();
  positions_.clear();
  positions_.reserve(samples.size());
  reset_point_lists(mesh);
  for (const SurfaceSample& s : samples) {
    const auto id = uint32_t(positions_.size());
    positions_.push_back(s.position);
    if (scalar_.enabled()) scalar_.add_point(mesh, s.face, s.position);
    if (s.vertex != kNoId) {
      parked_point_[s.vertex] = id;
    } else {
      face_points_[s.face].push_back({s.position, 0.0, id});
    }
  }
  // A face lists its points newest first, as collapsed() leaves them: the order of the sums
  // over a face's points is part of the build's arithmetic.
  for (auto& list : face_points_) std::reverse(list.begin(), list.end());
}

double EnergyPriority::diagonal_of(const CollapseMesh& mesh) const {
  return options_.reference_diagonal > 0 ? options_.reference_diagonal
                                         : bounding_box(mesh.positions()).diagonal();
}

void EnergyPriority::gather_face(FaceId f, int home) const {
  const auto& list = face_points_[f];
  const size_t first = scratch_.points.size();
  scratch_.points.insert(scratch_.points.end(), list.begin(), list.end());
  scratch_.homes.insert(scratch_.homes.end(), list.size(), home);
  if (drift_[f] != 0)  // rare: a face left with its points by a rich star's collapse
    for (size_t i = first; i < scratch_.points.size(); ++i)
      scratch_.points[i].distance_sq = bounded_distance_sq(f, scratch_.points[i]);
}

const PointMoments& EnergyPriority::moments_of(FaceId f) const {
  if (!moments_ready_[f]) {
    PointMoments m;
    double max_distance_sq = 0;
    for (const FacePoint& p : face_points_[f]) {
      m.add(p.position);
      max_distance_sq = std::max(max_distance_sq, p.distance_sq);
    }
    moments_[f] = m;
    max_distance_sq_[f] = max_distance_sq;
    moments_ready_[f] = 1;
  }
  return moments_[f];
}

const EnergyPriority::OwnError& EnergyPriority::own_error_of(const CollapseMesh& mesh,
                                                             FaceId f) const {
  if (moments_ready_[f] != 2) {
    const Triangle& t = mesh.face(f);
    const Vec3 &q0 = mesh.position(t[0]), &q1 = mesh.position(t[1]), &q2 = mesh.position(t[2]);
    own_[f] = {plane_distance_sq(f, q0, q1, q2), rim_sq(f, q0, q1, q2)};
    moments_ready_[f] = 2;
  }
  return own_[f];
}

// The squared distances of face f's points to the plane of (q0, q1, q2); to the triangle
// itself when it is too thin to have a plane.
double EnergyPriority::plane_distance_sq(FaceId f, const Vec3& q0, const Vec3& q1,
                                         const Vec3& q2) const {
  const PointMoments& m = moments_of(f);
  if (m.count == 0) return 0;
  const Vec3 n = triangle_normal(q0, q1, q2);
  const double n_sq = dot(n, n);
  if (has_plane(n_sq, q0, q1, q2)) return m.plane_distance_sq(q0, scale(n, 1.0 / std::sqrt(n_sq)));
  double sum = 0;
  for (const FacePoint& p : face_points_[f])
    sum += project_on_triangle(p.position, q0, q1, q2).distance_sq;
  return sum;
}

// A lower bound of how far face f's points lie outside the triangle (q0, q1, q2) within its
// plane, which the plane distances leave out: count x (the mean's in-plane distance)^2, since
// the squared distance to a convex set is convex (Jensen). With `star_face` (after the
// collapse, q0 the moving vertex) the mean may also lie on the faces beside it in the fan,
// as a point may move there. 0 for a thin triangle (measured exactly by plane_distance_sq).
double EnergyPriority::rim_sq(FaceId f, const Vec3& q0, const Vec3& q1, const Vec3& q2,
                              int star_face) const {
  const PointMoments& m = moments_of(f);
  if (m.count == 0) return 0;
  const Vec3 n = triangle_normal(q0, q1, q2);
  const double n_sq = dot(n, n);
  if (!has_plane(n_sq, q0, q1, q2)) return 0;
  // Inside (the common case): the mean's projection is on the left of every edge.
  const Vec3 e1 = sub(q1, q0), e2 = sub(q2, q0);
  const Vec3 w = sub(m.mean, q0);
  if (dot(cross(e1, w), n) >= 0 && dot(cross(w, e2), n) >= 0 &&
      dot(cross(sub(q2, q1), sub(m.mean, q1)), n) >= 0)
    return 0;
  const double h = dot(n, w);
  const double h_sq = h * h / n_sq;
  double closest = project_on_triangle(m.mean, q0, q1, q2).distance_sq;
  if (star_face >= 0)
    for (const int beside : {scratch_.star[star_face].next, scratch_.star[star_face].previous})
      if (beside >= 0 && closest > h_sq)
        closest = std::min(closest, project_on_triangle(m.mean, q0, scratch_.star[beside].p1,
                                                        scratch_.star[beside].p2)
                                        .distance_sq);
  return closest > h_sq ? m.count * (closest - h_sq) : 0;
}

// The change of the rim bound (rim_sq) over the star when the moving vertex goes to v. Added
// to the cost at the chosen placement only: the placements are compared on the planes.
double EnergyPriority::moment_rim_change(const CollapseMesh& mesh, const Vec3& v) const {
  double change = 0;
  for (size_t j = 0; j < scratch_.star.size(); ++j)
    change += rim_sq(scratch_.star[j].source, v, scratch_.star[j].p1, scratch_.star[j].p2, int(j)) -
              own_error_of(mesh, scratch_.star[j].source).rim_sq;
  for (int e = 0; e < 2; ++e)
    if (const FaceId f = scratch_.edge_faces[e]; f != kNoId) {
      const StarFace& home = scratch_.star[scratch_.edge_face_homes[e]];
      change += rim_sq(f, v, home.p1, home.p2, scratch_.edge_face_homes[e]) -
                own_error_of(mesh, f).rim_sq;
    }
  return change;
}

// E_dist of a star too rich in points to project each one, in O(faces of the star): each
// face's points are measured against its plane (by their moments), before and after alike, so
// that the error of a point whose closest point is on a face's rim, not inside, is left out of
// both rather than one. Only the samples of a and b (parked, at distance 0 before) are
// projected one by one.
double EnergyPriority::moment_distance_before(const CollapseMesh& mesh) const {
  double sum = 0;
  for (const StarFace& f : scratch_.star) sum += own_error_of(mesh, f.source).plane_sq;
  for (const FaceId f : scratch_.edge_faces)
    if (f != kNoId) sum += own_error_of(mesh, f).plane_sq;
  return sum;
}

double EnergyPriority::moment_distance_after(const Vec3& v) const {
  double sum = 0;
  for (const StarFace& f : scratch_.star) sum += plane_distance_sq(f.source, v, f.p1, f.p2);
  for (int e = 0; e < 2; ++e)
    if (scratch_.edge_faces[e] != kNoId) {
      const StarFace& home = scratch_.star[scratch_.edge_face_homes[e]];
      sum += plane_distance_sq(scratch_.edge_faces[e], v, home.p1, home.p2);
    }
  if (!scratch_.parked_ends.empty())
    sum += project_points(scratch_.parked_ends, scratch_.parked_end_homes, v).distance_sq;
  return sum;
}

// One step of iteratively reweighted least squares on the planes: each face's |n(v)|^2 taken
// at `from`, the rest is quadratic in v (add_plane_quadratic); `iso_a` |v|^2 - 2 iso_b.v are
// the springs' and the curves' terms, as in the projection solve. `model`: the planes' and the
// parked ends' part of what was minimised.
Vec3 EnergyPriority::moment_solve(const Vec3& from, double iso_a, const Vec3& iso_b,
                                  PlaneModel* model) const {
  PlaneModel planes;
  auto add_face = [&](FaceId source, const Vec3& p1, const Vec3& p2) {
    const PointMoments& m = moments_of(source);
    if (m.count == 0) return;
    const Vec3 n = triangle_normal(from, p1, p2);
    const double n_sq = dot(n, n);
    if (n_sq > 0) add_plane_quadratic(m, p1, p2, 1.0 / n_sq, planes.h, planes.r, planes.k);
  };
  for (const StarFace& f : scratch_.star) add_face(f.source, f.p1, f.p2);
  for (int e = 0; e < 2; ++e)
    if (scratch_.edge_faces[e] != kNoId)
      add_face(scratch_.edge_faces[e], scratch_.star[scratch_.edge_face_homes[e]].p1,
               scratch_.star[scratch_.edge_face_homes[e]].p2);
  if (!scratch_.parked_ends.empty())
    planes.ends = project_points(scratch_.parked_ends, scratch_.parked_end_homes, from);
  Eigen::Matrix3d h = planes.h + Eigen::Matrix3d::Identity() * (iso_a + planes.ends.a);
  Eigen::Vector3d r =
      planes.r + Eigen::Vector3d(iso_b[0] + planes.ends.b[0], iso_b[1] + planes.ends.b[1],
                                 iso_b[2] + planes.ends.b[2]);
  if (star_terms_on_) {
    // The star's quadric is about scratch_.origin: (v - o)^T A (v - o) + 2 b.(v - o) + c.
    const Quadric& q = scratch_.terms;
    Eigen::Matrix3d a;
    a << q.a00, q.a01, q.a02, q.a01, q.a11, q.a12, q.a02, q.a12, q.a22;
    const Eigen::Vector3d o(scratch_.origin[0], scratch_.origin[1], scratch_.origin[2]);
    h += a;
    r += a * o - Eigen::Vector3d(q.b0, q.b1, q.b2);
  }
  if (model) *model = planes;
  const Eigen::LDLT<Eigen::Matrix3d> solver(h);
  const Eigen::Vector3d v = solver.solve(r);
  if (solver.info() != Eigen::Success || !v.allFinite()) return from;
  return {v[0], v[1], v[2]};
}

// The minimiser of the projected points' model (fit), iso_a |v|^2 - 2 iso_b.v (the springs'
// and the curves' terms) and the star's terms; `from` when there is none.
Vec3 EnergyPriority::projection_solve(const Fit& fit, double iso_a, const Vec3& iso_b,
                                      const Vec3& from) const {
  const double diagonal = fit.a + iso_a;
  if (!(diagonal > 0)) return from;
  const Vec3 pull = add(fit.b, iso_b);
  if (star_terms_on_) {
    // In coordinates about scratch_.origin (u = v - o), where the star's quadric is kept: the
    // isotropic part d |u + o|^2 - 2 pull.(u + o) adds d to A's diagonal and d o - pull to b.
    Quadric q = scratch_.terms;
    const Vec3& o = scratch_.origin;
    q.a00 += diagonal, q.a11 += diagonal, q.a22 += diagonal;
    q.b0 += diagonal * o[0] - pull[0], q.b1 += diagonal * o[1] - pull[1];
    q.b2 += diagonal * o[2] - pull[2];
    Vec3 u;
    if (q.minimizer(u, 0)) return add(u, o);  // positive definite: no threshold
  }
  // Without the star's terms the model is isotropic: a scalar times the identity.
  return scale(pull, 1.0 / diagonal);
}

double EnergyPriority::exact_distance_sq() const {
  double sum = 0;
  for (const FacePoint& p : scratch_.points) sum += p.distance_sq;
  return sum;
}

void EnergyPriority::unpark(VertexId v) {
  const uint32_t id = parked_point_[v];
  if (id == kNoPoint) return;
  parked_point_[v] = kNoPoint;
  scratch_.points.push_back(parked(id));
}

EnergyPriority::Fit EnergyPriority::project_points(const std::vector<FacePoint>& points,
                                                   const std::vector<int>& homes, const Vec3& v,
                                                   std::vector<Projected>* where) const {
  Fit fit;
  if (where) where->resize(points.size());
  if (points.empty()) return fit;
  // Every face up front: a star's few points (5 on 8 faces, typically: most samples are
  // parked at their vertices) touch nearly all of them, and the loop below stays small.
  scratch_.prepared.resize(scratch_.star.size());
  for (size_t j = 0; j < scratch_.star.size(); ++j)
    scratch_.prepared[j].reset(v, scratch_.star[j].p1, scratch_.star[j].p2);
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3& x = points[i].position;
    // A point moves at most one face along the fan per projection: its face's image and the
    // two faces beside it. (The performed collapse projects onto the whole star.)
    Projection best;
    best.distance_sq = std::numeric_limits<double>::infinity();
    int best_j = 0;
    auto consider = [&](int j) {
      const Projection p = scratch_.prepared[j].project(x);
      if (p.distance_sq < best.distance_sq) best = p, best_j = j;
    };
    // A face whose plane is already farther than the best cannot win.
    auto consider_near = [&](int j) {
      if (scratch_.prepared[j].plane_distance_sq(x) <= best.distance_sq) consider(j);
    };
    const int home = homes[i];
    if (home < 0) {
      // The sample of a (b), at a's old position: v moved away from it, towards the other
      // end, so it lies over the faces that were a's (b's).
      const bool a_side = home == -1;
      int begin = a_side ? 0 : scratch_.a_side_faces,
          end = a_side ? scratch_.a_side_faces : int(scratch_.star.size());
      if (x == v) {
        // At the start where v is that end: on the first face, at distance 0, as projecting
        // onto each face (all meet at v) would find.
        best = {{1, 0, 0}, 0};
        best_j = begin < end ? begin : 0;
      } else {
        if (begin == end) begin = 0, end = int(scratch_.star.size());
        for (int j = begin; j < end; ++j) consider_near(j);
      }
    } else {
      consider(home);
      if (scratch_.star[home].next >= 0) consider_near(scratch_.star[home].next);
      if (scratch_.star[home].previous >= 0) consider_near(scratch_.star[home].previous);
    }
    const StarFace* best_face = &scratch_.star[best_j];
    if (where) (*where)[i] = {best_j, best.bary};
    fit.distance_sq += best.distance_sq;
    fit.max_distance_sq = std::max(fit.max_distance_sq, best.distance_sq);
    const double b0 = best.bary[0];
    fit.a += b0 * b0;
    const Vec3 rest = add(scale(best_face->p1, best.bary[1]), scale(best_face->p2, best.bary[2]));
    const Vec3 offset = sub(x, rest);
    fit.b = add(fit.b, scale(offset, b0));
    fit.c += dot(offset, offset);
  }
  return fit;
}

bool EnergyPriority::folds(const Vec3& v) const {
  for (const StarFace& f : scratch_.star)
    if (face_folds(f.before, f.p1, f.p2, v, f.p1, f.p2)) return true;
  return false;
}

EnergyPriority::Survivor EnergyPriority::choose_survivor(const CollapseMesh& mesh, VertexId a,
                                                         VertexId b) const {
  const bool locked_a = !locked_.empty() && locked_[a];
  const bool locked_b = !locked_.empty() && locked_[b];
  if (locked_a && locked_b) return {};
  const bool boundary_a = mesh.is_boundary(a), boundary_b = mesh.is_boundary(b);
  // Discontinuity curves (boundaries, creases, seams): a vertex on a curve does not leave
  // it for an inner vertex, nor a curve's corner or end (not two sharp edges) for a vertex
  // along it; a collapse that changes the curves' topology keeps vs in place and pays.
  const bool curve_a = boundary_a || curves_.on_curve(a);
  const bool curve_b = boundary_b || curves_.on_curve(b);
  const bool corner_a = curves_.on_curve(a) && curves_.sharp_neighbors(a).size() != 2;
  const bool corner_b = curves_.on_curve(b) && curves_.sharp_neighbors(b).size() != 2;
  const bool topology = curves_.changes_topology(a, b);
  // Which end survives: a locked end, else the end on a curve, else a corner, else the
  // smaller id.
  bool keep_b;
  if (locked_a || locked_b) {
    keep_b = locked_b;
  } else if (curve_a != curve_b) {
    keep_b = curve_b;
  } else if (corner_a != corner_b) {
    keep_b = corner_b;
  } else {
    keep_b = b < a;
  }
  const bool fixed = locked_a || locked_b || curve_a != curve_b || corner_a != corner_b || topology;
  return {true, keep_b, fixed, topology, boundary_a, boundary_b};
}

EnergyPriority::StarSums EnergyPriority::gather_star(const CollapseMesh& mesh, VertexId a,
                                                     VertexId b) const {
  // The star: every face around a or b; after the collapse those without both ends remain,
  // with the moving corner first. Points of the two faces that disappear are homed next to
  // their apex once the fan is known.
  scratch_.star.clear();
  scratch_.lists.clear();
  scratch_.points.clear();
  scratch_.homes.clear();
  std::array<VertexId, 2> edge_apexes{kNoId, kNoId};
  int edge_faces = 0;
  scratch_.edge_faces = {kNoId, kNoId};
  scratch_.joined_count = 0;
  // The star's planes before the collapse (area weighted), the sum of its faces' normals and
  // of normal.corner (the tetrahedra between v and the faces have signed volumes summing to
  // (normals.v - offsets) / 6), and twice its area; about a's position, so that the quadric's
  // value, a small difference of large terms far from the model's origin, stays exact.
  scratch_.origin = mesh.position(a);
  Quadric star_planes;
  Vec3 normals{};
  double offsets = 0, area2 = 0;
  for (VertexId end : {a, b}) {
    if (end == b) scratch_.a_side_faces = int(scratch_.star.size());
    const VertexId other = end == a ? b : a;
    for (FaceId f : mesh.faces_of(end)) {
      const Triangle& t = mesh.face(f);
      const int k = corner_of(t, end);
      const int other_corner = corner_of(t, other);
      if (end == b && other_corner >= 0) continue;  // seen from a
      const Vec3& p0 = mesh.position(end);
      const Vec3& p1 = mesh.position(t[(k + 1) % 3]);
      const Vec3& p2 = mesh.position(t[(k + 2) % 3]);
      if (star_terms_on_) {
        const Vec3 n = triangle_normal(p0, p1, p2);
        const double n_length = length(n);
        const double offset = dot(n, sub(p0, scratch_.origin));
        normals = add(normals, n);
        offsets += offset;
        area2 += n_length;
        if (n_length > 0)
          star_planes += Quadric::from_plane(scale(n, 1 / n_length), -offset / n_length, n_length);
      }
      if (other_corner >= 0) {
        if (edge_faces < 2) {
          edge_apexes[edge_faces] = t[3 - k - other_corner];
          if (scalar_.enabled()) {
            const auto& w = mesh.corner_wedges(f);
            scratch_.joined[scratch_.joined_count++] = {w[k], w[other_corner]};
          }
          scratch_.edge_faces[edge_faces] = f;
          scratch_.lists.push_back({f, -2 - edge_faces});
          ++edge_faces;
        }
      } else {
        scratch_.star.push_back({p1, p2, p0, t[(k + 1) % 3], t[(k + 2) % 3]});
        scratch_.star.back().source = f;
        if (scalar_.enabled()) {
          const auto& w = mesh.corner_wedges(f);
          scratch_.star.back().wedges = {w[k], w[(k + 1) % 3], w[(k + 2) % 3]};
        }
        scratch_.lists.push_back({f, int(scratch_.star.size()) - 1});
      }
    }
  }
  return {star_planes, normals, offsets, area2, edge_apexes, edge_faces};
}

double EnergyPriority::link_fan(const StarSums& sums, VertexId a, VertexId b) const {
  // The fan around the moved vertex, and homes for the points of the two removed faces.
  std::array<int, 2> apex_home{0, 0};
  double parked_around = 0;
  // Linking is quadratic in the valence: scan packed ids, not the star's faces.
  scratch_.fan_first_ids.clear();
  scratch_.fan_second_ids.clear();
  for (const StarFace& face : scratch_.star) {
    scratch_.fan_first_ids.push_back(face.id1);
    scratch_.fan_second_ids.push_back(face.id2);
  }
  const int star_size = int(scratch_.star.size());
  for (int j = 0; j < star_size; ++j) {
    StarFace& face = scratch_.star[j];
    const VertexId first = face.id1, second = face.id2;
    // Branch-free (the last match wins), so that the compiler vectorises the scan.
    int next = face.next, previous = face.previous;
    for (int k = 0; k < star_size; ++k) {
      next = scratch_.fan_first_ids[k] == second ? k : next;
      previous = scratch_.fan_second_ids[k] == first ? k : previous;
    }
    face.next = next;
    face.previous = previous;
    for (int e = 0; e < sums.edge_faces; ++e)
      if (face.id1 == sums.edge_apexes[e] || face.id2 == sums.edge_apexes[e]) apex_home[e] = j;
    // A neighbour's parked sample sits on the star's rim: half of it counts as the star's.
    if (parked_point_[face.id1] != kNoPoint) parked_around += 0.5;
  }
  scratch_.edge_face_homes = apex_home;
  // The samples of a and b themselves, where they still are.
  scratch_.parked_ends.clear();
  scratch_.parked_end_homes.clear();
  for (VertexId end : {a, b})
    if (parked_point_[end] != kNoPoint) {
      scratch_.parked_ends.push_back(parked(parked_point_[end]));
      scratch_.parked_end_homes.push_back(end == a ? -1 : -2);
    }
  return parked_around;
}

EnergyPriority::StarPoints EnergyPriority::gather_star_points(double parked_around) const {
  // How many points the star holds: the faces' counts are their moments' (kept per face).
  size_t in_faces = 0;
  for (const auto& list : scratch_.lists) in_faces += face_points_[list.first].size();
  const size_t total = in_faces + scratch_.parked_ends.size();
  const double points_around = double(total) + parked_around;
  const size_t cap = std::max<uint32_t>(1, options_.max_points_per_evaluation);
  // A star with more points than cap is placed and costed on its faces' point moments, in
  // O(faces) whatever its points (moment_solve, moment_distance_after): late collapses cover
  // hundreds of points. A smaller one projects each point, exactly. With E_scalar the points
  // are gathered either way: the attributes need where each one lands.
  const bool by_moments = total > cap;
  scratch_.point_weight = 1;
  const size_t sampled = options_.max_sampled_points;
  auto gather_all = [&] {
    for (const auto& [f, home] : scratch_.lists)
      gather_face(f, home < 0 ? scratch_.edge_face_homes[-2 - home] : home);
    scratch_.points.insert(scratch_.points.end(), scratch_.parked_ends.begin(),
                           scratch_.parked_ends.end());
    scratch_.homes.insert(scratch_.homes.end(), scratch_.parked_end_homes.begin(),
                          scratch_.parked_end_homes.end());
  };
  if (!by_moments || (scalar_.enabled() && (sampled == 0 || total <= sampled))) {
    gather_all();
  } else if (scalar_.enabled()) {
    // About one point in k stands for k: E_scalar costs each point it sees.
    const size_t stride = (total + sampled - 1) / sampled;
    auto take = [&](const FacePoint& p, int home) {
      if (!kept_when_thinned(point_id_.empty() ? p.id : point_id_[p.id], stride)) return;
      scratch_.points.push_back(p);
      scratch_.homes.push_back(home);
    };
    for (const auto& [f, home] : scratch_.lists)
      for (const FacePoint& p : face_points_[f])
        take(p, home < 0 ? scratch_.edge_face_homes[-2 - home] : home);
    for (size_t i = 0; i < scratch_.parked_ends.size(); ++i)
      take(scratch_.parked_ends[i], scratch_.parked_end_homes[i]);
    if (scratch_.points.empty()) {
      gather_all();
    } else {
      scratch_.point_weight = double(total) / double(scratch_.points.size());
    }
  }
  return {by_moments, points_around};
}

void EnergyPriority::set_star_terms(StarSums& sums, double points_around) const {
  if (star_terms_on_) {
    // Points spread at density rho = points / area over a face of the star, v moving by h off
    // its plane, are moved by h times their barycentric coordinate of v: rho area h^2 / 6 in
    // all. The volume's change over the star's area is a mean displacement of
    // (sums.normals.v - sums.offsets) / (3 sums.area2), for all the star's points.
    const double points = std::max(1.0, points_around);
    scratch_.terms = Quadric{};
    if (sums.area2 > 0 && options_.star_planes_weight > 0) {
      sums.planes *= options_.star_planes_weight * points / (6 * sums.area2);
      scratch_.terms += sums.planes;
    }
    const double normals_length = length(sums.normals);
    if (sums.area2 > 0 && normals_length > 0 && options_.volume_weight > 0) {
      Quadric volume =
          Quadric::from_plane(scale(sums.normals, 1 / normals_length),
                              -sums.offsets / normals_length, normals_length * normals_length);
      volume *= options_.volume_weight * points / (9 * sums.area2 * sums.area2);
      scratch_.terms += volume;
    }
  }
}

bool EnergyPriority::evaluate(const CollapseMesh& mesh, VertexId a, VertexId b,
                              CollapseCandidate& out, Costing costing) const {
  ++costings_;
  const Survivor survivor = choose_survivor(mesh, a, b);
  if (!survivor.possible) return false;
  const bool keep_b = survivor.keep_b, fixed = survivor.fixed, topology = survivor.topology;
  const bool boundary_a = survivor.boundary_a, boundary_b = survivor.boundary_b;
  out.vs = keep_b ? b : a;
  out.vt = keep_b ? a : b;
  const Vec3& pa = mesh.position(a);
  const Vec3& pb = mesh.position(b);

  StarSums sums = gather_star(mesh, a, b);
  if (scratch_.star.empty()) return false;
  const double parked_around = link_fan(sums, a, b);
  const StarPoints points = gather_star_points(parked_around);
  const bool by_moments = points.by_moments;
  const double points_around = points.points_around;
  curves_.gather(a, b, mesh, options_.max_sampled_points);
  const double curve_before = curves_.gathered_distance_sq();
  const double distance_before = by_moments ? moment_distance_before(mesh) : exact_distance_sq();

  const double kappa =
      options_.spring_scale * spring_constant(points_around / double(scratch_.star.size()));
  Vec3 spring_pull{};  // kappa/2 * sum (p1 + p2): the springs' part of the normal equations
  for (const StarFace& f : scratch_.star) spring_pull = add(spring_pull, add(f.p1, f.p2));
  spring_pull = scale(spring_pull, 0.5 * kappa);
  const double spring_weight = kappa * double(scratch_.star.size());
  set_star_terms(sums, points_around);

  // 6. Placements: the fixed survivor's place, or from each start a measure and solves
  //    (fewer starts for a queue key); 7. the lowest that folds no face, priced.
  static constexpr size_t kNotProjected = ~size_t{0};
  struct Placement {
    Vec3 v;
    double energy;
    double max_distance_sq;
    size_t index;  // into scratch_.placement_projections; kNotProjected for a modelled placement
  };
  std::array<Placement, 16> placements;
  size_t placed = 0;
  SharpCurves::Fit curve_fit;
  // With E_scalar and every point projected, each placement keeps its projections, so that
  // the chosen one's need not be computed again.
  const bool keep_projections = scalar_.enabled() && !by_moments;
  auto measure = [&](const Vec3& v, Fit& fit) {
    if (by_moments) {
      fit = Fit{};
      fit.distance_sq = moment_distance_after(v);
    } else {
      fit = project_points(scratch_.points, scratch_.homes, v,
                           keep_projections && placed < placements.size()
                               ? &scratch_.placement_projections[placed]
                               : nullptr);
    }
    curve_fit = curves_.gathered() ? curves_.project(v) : SharpCurves::Fit{};
    double energy = fit.distance_sq + curve_fit.distance_sq;
    if (star_terms_on_) energy += scratch_.terms.evaluate(sub(v, scratch_.origin));
    if (placed < placements.size()) {
      placements[placed] = {v, energy, std::max(fit.max_distance_sq, curve_fit.max_distance_sq),
                            placed};
      ++placed;
    }
  };
  PlaneModel plane_model;
  auto solve = [&](const Fit& fit, const Vec3& from) -> Vec3 {
    Vec3 v;
    if (by_moments) {
      v = moment_solve(from, curve_fit.a + spring_weight, add(curve_fit.b, spring_pull),
                       &plane_model);
    } else {
      v = projection_solve(fit, curve_fit.a + spring_weight, add(curve_fit.b, spring_pull), from);
    }
    if (boundary_a && boundary_b && !curves_.has_samples()) {
      // Without curve samples (discontinuities off), a boundary edge keeps its vertex on the
      // segment, so that the boundary keeps its place (the projection: the constrained
      // optimum of an isotropic energy, near it with the star's terms).
      v = add(pa, scale(sub(pb, pa), project_on_segment(v, pa, pb).t));
    }
    return rounded(v, options_.round_to_float);
  };

  Fit fit;
  if (fixed) {
    measure(mesh.position(out.vs), fit);
  } else {
    const Vec3 mid = rounded(scale(add(pa, pb), 0.5), options_.round_to_float);
    // A queue key starts from fewer places than the performed collapse, which tries all three:
    // a young star projected point by point (an end still holds its own sample, which is on
    // the input surface) from the two ends, a star costed by moments from the midpoint only
    // (its solve is the dear part). A projected star's key is still an upper bound of the cost
    // measured at the top, looser where the midpoint's start would win: such edges come a little
    // later. Chosen by measurement: faster, and no level worse (decisions/notebook-2026-11.md,
    // "Queue keys from fewer starts").
    std::array<Vec3, 3> starts{pa, pb, mid};
    std::span<const Vec3> tried(starts);
    if (costing == Costing::kQueue) {
      if (by_moments) {
        tried = tried.subspan(2);
      } else if (!scratch_.parked_ends.empty()) {
        tried = tried.first(2);
      }
    }
    for (const Vec3& start : tried) {
      Vec3 v = start;
      measure(v, fit);
      for (int i = 0; i < options_.solves_per_start; ++i) {
        v = solve(fit, v);
        if (costing == Costing::kQueue && i + 1 == options_.solves_per_start) {
          // A queue key: the last solve is costed on the model it minimised, not measured
          // again, which halves the projections. For projected points the model is an upper
          // bound of the measured energy (each point's barycentric coordinates put it on a
          // face of the new star), so the key errs towards later, never earlier; the moments'
          // model is the reweighted planes'. The collapse is measured when it is performed.
          if (placed < placements.size()) {
            const double distance = by_moments ? plane_model.at(v) : fit.model_at(v);
            double energy = distance + curve_fit.model_at(v);
            if (star_terms_on_) energy += scratch_.terms.evaluate(sub(v, scratch_.origin));
            placements[placed++] = {v, energy, 0, kNotProjected};
          }
          break;
        }
        measure(v, fit);
      }
    }
  }

  // The lowest energy among the placements that fold no face (the face-geometry constraint
  // would veto the others); if all fold, the lowest (and the constraint vetoes it).
  std::sort(placements.begin(), placements.begin() + placed,
            [](const Placement& x, const Placement& y) { return x.energy < y.energy; });
  const Placement* chosen = &placements[0];
  for (size_t i = 0; i < placed; ++i)
    if (!folds(placements[i].v)) {
      chosen = &placements[i];
      break;
    }
  out.position = chosen->v;
  out.cost = chosen->energy - distance_before - curve_before;
  out.error = std::sqrt(chosen->max_distance_sq);
  if (by_moments) out.cost += moment_rim_change(mesh, chosen->v);
  // E_scalar wants every point's projection at the chosen placement.
  if (keep_projections && chosen->index != kNotProjected) {
    scratch_.projected.swap(scratch_.placement_projections[chosen->index]);
  } else if (scalar_.enabled()) {
    project_points(scratch_.points, scratch_.homes, chosen->v, &scratch_.projected);
  }
  // E_scalar counts the star's points; the star's planes stand for star_planes_weight times as
  // many between them, which carry attributes too, so the attributes' change is weighted as
  // over all of them: else the geometry would outweigh the attributes star_planes_weight times
  // more than E_scalar's weight says.
  if (scalar_.enabled()) out.cost += (1 + options_.star_planes_weight) * scalar_change();
  // Penalised, not forbidden (Hoppe 96), at a price per point of the star.
  if (topology) out.cost += topology_price_ * std::max(1.0, points_around);
  return std::isfinite(out.cost);
}

// The change of E_scalar over the star's points, projected as in scratch_.projected, with the
// wedges of the moving vertex at their best values.
double EnergyPriority::scalar_change() const {
  scalar_.begin_star(scratch_.joined, scratch_.joined_count);
  for (StarFace& face : scratch_.star) face.group = scalar_.group_of(face.wedges[0]);
  double before = 0;
  for (size_t i = 0; i < scratch_.points.size(); ++i) {
    const uint32_t id = scratch_.points[i].id;
    const Projected& p = scratch_.projected[i];
    const StarFace& face = scratch_.star[p.face];
    scalar_.add(face.group, id, p.bary[0], face.wedges[1], p.bary[1], face.wedges[2], p.bary[2]);
    before += scalar_.residual(id);
  }
  return (scalar_.star_energy() - before) * scratch_.point_weight;
}

// E_scalar after a performed collapse: the wedges joined for good, the star's wedges given the
// values that fit the star's points as they now project, and the points' errors updated.
void EnergyPriority::update_attributes(const CollapseMesh& mesh, CollapseCandidate& done,
                                       const EdgeFaces& edge) {
  for (FaceId f : {edge.left, edge.right}) {
    if (f == kNoId) continue;
    const Triangle& t = mesh.face(f);  // a removed face keeps its corners
    const auto& w = mesh.corner_wedges(f);
    scalar_.join(w[corner_of(t, done.vs)], w[corner_of(t, done.vt)]);
  }
  scalar_.begin_star({}, 0);
  // Every wedge at vs takes part, also on faces no point projects onto.
  for (FaceId f : mesh.faces_of(done.vs))
    scalar_.group_of(mesh.corner_wedges(f)[corner_of(mesh.face(f), done.vs)]);
  auto corners = [&](FaceId f, int k) {
    const auto& w = mesh.corner_wedges(f);
    return std::array<WedgeId, 3>{w[k], w[(k + 1) % 3], w[(k + 2) % 3]};
  };
  for (size_t i = 0; i < scratch_.points.size(); ++i) {
    const FaceId f = moved_faces_[i];
    const int k = corner_of(mesh.face(f), done.vs);
    const auto& b = moved_bary_[i];
    const auto w = corners(f, k);
    scalar_.add(scalar_.group_of(w[0]), scratch_.points[i].id, b[k], w[1], b[(k + 1) % 3], w[2],
                b[(k + 2) % 3]);
  }
  scalar_.apply(done.changed_wedges, done.changed_values);
  for (size_t i = 0; i < scratch_.points.size(); ++i) {
    const FaceId f = moved_faces_[i];
    const uint32_t id = scratch_.points[i].id;
    scalar_.set_residual(id, scalar_.residual_against(id, mesh.corner_wedges(f), moved_bary_[i]));
  }
}

void EnergyPriority::collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                               const EdgeFaces& edge) {
  // Every point of the old star goes to its closest face of the new one; so do the samples
  // of vt (removed) and of vs if it moved. A star too rich in points moves only those of the
  // removed faces and the samples (see the header).
  const auto& faces = mesh.faces_of(done.vs);
  size_t in_star = 0;
  for (FaceId f : {edge.left, edge.right})
    if (f != kNoId) in_star += face_points_[f].size();
  for (FaceId f : faces) in_star += face_points_[f].size();
  const uint32_t cap = options_.max_points_per_reprojection;
  const bool keep_faces = !scalar_.enabled() && cap > 0 && in_star > cap;
  auto index_of = [&](VertexId corner) {
    for (size_t j = 0; j < faces.size(); ++j)
      if (corner_of(mesh.face(faces[j]), corner) >= 0) return int(j);
    return -1;
  };
  scratch_.points.clear();
  scratch_.homes.clear();
  auto take = [&](FaceId f, int home) {
    auto& list = face_points_[f];
    scratch_.points.insert(scratch_.points.end(), list.begin(), list.end());
    scratch_.homes.insert(scratch_.homes.end(), list.size(), home);
    list.clear();
    moments_ready_[f] = 0;
    drift_[f] = 0;
  };
  for (const auto& [removed, apex] :
       {std::pair{edge.left, edge.left_apex}, std::pair{edge.right, edge.right_apex}})
    if (removed != kNoId) {
      // (Its stored distances may lag: moved again, each point's is computed anew.)
      take(removed, index_of(apex));
      face_points_[removed].shrink_to_fit();
    }
  if (!keep_faces)
    for (size_t j = 0; j < faces.size(); ++j) take(faces[j], int(j));
  unpark(done.vt);
  const uint32_t vs_sample = parked_point_[done.vs];
  // vs's own sample stays exact while vs stays put, unless E_scalar gives its wedges new
  // values.
  if (vs_sample != kNoPoint && (positions_[vs_sample] != done.position || scalar_.enabled()))
    unpark(done.vs);
  scratch_.homes.resize(scratch_.points.size(), -1);  // the unparked samples: no home
  double max_distance_sq = curves_.collapsed(done.vs, done.vt, mesh);
  if (faces.empty()) return;
  if (keep_faces) {
    // A point's closest point on a face of the fan is b0 v + b1 p1 + b2 p2, with v where vs
    // or vt was: it moves by at most b0 |v - old|.
    const Vec3 to_s = sub(done.position, done.vs_before);
    const Vec3 to_t = sub(done.position, mesh.position(done.vt));  // (vt keeps its position)
    const double shift = std::sqrt(std::max(dot(to_s, to_s), dot(to_t, to_t)));
    for (FaceId f : faces) {
      if (face_points_[f].empty()) continue;
      moments_of(f);
      moments_ready_[f] = 1;  // the points are the same, the corners not
      drift_[f] += shift;
      const double bound = std::sqrt(max_distance_sq_[f]) + drift_[f];
      max_distance_sq = std::max(max_distance_sq, bound * bound);
    }
  }
  prepare_fan(mesh, done.vs);
  moved_faces_.resize(scratch_.points.size());
  moved_bary_.resize(scratch_.points.size());
  // Last point first: each face then lists its points newest first (see initialize()).
  for (size_t i = scratch_.points.size(); i-- > 0;) {
    FacePoint& point = scratch_.points[i];
    const auto [j, best] = closest_fan_face(mesh, faces, point, scratch_.homes[i]);
    const FaceId face = faces[j];
    moved_faces_[i] = face;
    moved_bary_[i] = best.bary;
    point.distance_sq = best.distance_sq;
    face_points_[face].push_back(point);
    moments_ready_[face] = 0;
    max_distance_sq = std::max(max_distance_sq, best.distance_sq);
  }
  if (scalar_.enabled()) update_attributes(mesh, done, edge);
  // The largest distance of the star's points, where the evaluation may have looked at a
  // subset.
  done.error = std::sqrt(max_distance_sq);
}

// The faces around vs after a collapse, prepared for projections, with what closest_fan_face
// bounds distances by (FanFace).
void EnergyPriority::prepare_fan(const CollapseMesh& mesh, VertexId vs) {
  const auto& faces = mesh.faces_of(vs);
  scratch_.prepared.clear();
  fan_.clear();
  for (FaceId f : faces) {
    const Triangle& t = mesh.face(f);
    const Vec3 &p0 = mesh.position(t[0]), &p1 = mesh.position(t[1]), &p2 = mesh.position(t[2]);
    scratch_.prepared.emplace_back(p0, p1, p2);
    FanFace fan;
    fan.center = scale(add(add(p0, p1), p2), 1.0 / 3);
    double radius_sq = 0;
    for (const Vec3* p : {&p0, &p1, &p2}) {
      const Vec3 d = sub(*p, fan.center);
      radius_sq = std::max(radius_sq, dot(d, d));
    }
    fan.radius = std::sqrt(radius_sq);
    const Vec3 n = triangle_normal(p0, p1, p2);
    const double n_sq = dot(n, n);
    if (n_sq > 0) fan.normal = scale(n, 1.0 / std::sqrt(n_sq));
    fan_.push_back(fan);
  }
}

// The face of the fan (prepare_fan) a point goes to: the closest, the first in the fan's order
// among equally close ones (as if each were tried in turn), and the point's projection there.
// Late collapses move hundreds of points over a fan of 6-8 faces: the face the point was on
// (its home) is tried first, and a face is skipped without projecting when a lower bound of
// the distance (the height over its plane, and how far outside a disc holding it the point
// lies) exceeds the best so far. With E_scalar the points go where their whole energy is least
// (a point on a seam is as close to the faces of both sides and belongs to the side whose
// attributes it has); the distance is a lower bound of that too.
std::pair<int, Projection> EnergyPriority::closest_fan_face(const CollapseMesh& mesh,
                                                            const std::vector<FaceId>& faces,
                                                            const FacePoint& point,
                                                            int home) const {
  const Vec3& x = point.position;
  int best_j = -1;
  Projection best;
  double best_score = std::numeric_limits<double>::infinity();
  auto consider = [&](int j) {
    const Projection p = scratch_.prepared[j].project(x);
    const double score = scalar_.enabled()
                             ? p.distance_sq + scalar_.residual_against(
                                                   point.id, mesh.corner_wedges(faces[j]), p.bary)
                             : p.distance_sq;
    if (score < best_score || (score == best_score && j < best_j)) {
      best_score = score, best = p, best_j = j;
    }
  };
  if (home >= 0) consider(home);
  for (int j = 0; j < int(faces.size()); ++j) {
    if (j == home) continue;
    // A lower bound of the squared distance to face j: the height over its plane, and how far
    // outside the disc around its centroid that holds it the point lies within the plane.
    const FanFace& fan = fan_[j];
    const Vec3 d = sub(x, fan.center);
    const double height = dot(fan.normal, d);
    // (A margin, relative to the face's size, keeps rounding from skipping a face that ties.)
    const double limit = best_score + 1e-9 * (best_score + fan.radius * fan.radius);
    const double height_sq = height * height;
    if (height_sq > limit) continue;
    const double in_plane_sq = dot(d, d) - height_sq;
    if (in_plane_sq > fan.radius * fan.radius) {
      const double outside = std::sqrt(in_plane_sq) - fan.radius;
      if (height_sq + outside * outside > limit) continue;
    }
    consider(j);
  }
  if (best_j < 0) {  // nothing finite: the first face, as the exhaustive scan would
    best_j = 0;
    best = scratch_.prepared[0].project(x);
  }
  return {best_j, best};
}

}  // namespace parapm
