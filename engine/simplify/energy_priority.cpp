#include "simplify/energy_priority.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "simplify/face_fold.h"
#include "simplify/point_projection.h"
#include "simplify/surface_samples.h"
#include "simplify/vec_math.h"

namespace parapm {
namespace {

// Half the squared lengths of a face's edges: summed over faces, an interior edge counts
// once (it has two faces) and a boundary edge half, which is all the spring term needs.
double half_edges_sq(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub(b, a), bc = sub(c, b), ca = sub(a, c);
  return 0.5 * (dot(ab, ab) + dot(bc, bc) + dot(ca, ca));
}

Vec3 rounded(Vec3 v, bool to_float) {
  if (to_float)
    for (double& c : v) c = round_to_float(c);
  return v;
}

}  // namespace

double spring_constant(double points_per_face) {
  if (points_per_face < 4) return 1e-2;
  if (points_per_face < 8) return 1e-4;
  return 1e-8;
}

void EnergyPriority::initialize(const CollapseMesh& mesh) {
  const std::vector<SurfaceSample> samples =
      sample_surface(mesh, options_.samples_per_face, options_.seed);
  if (options_.discontinuities) {
    curves_.initialize(mesh, options_.sharp);
  } else {
    curves_ = SharpCurves{};
    curves_.initialize_empty(mesh);
  }
  // Large against any ordinary change of energy: (bounding-box diagonal)^2 per vertex.
  const double diagonal = bounding_box(mesh.positions()).diagonal();
  topology_penalty_ = diagonal * diagonal * double(std::max<size_t>(1, mesh.live_vertices()));

  const bool scalar = mesh.has_wedges() && attributes_.layout.any();
  scalar_.initialize(scalar ? attributes_.layout : AttributeLayout{}, attributes_.values,
                     options_.attribute_weight * diagonal);

  points_.clear();
  points_.reserve(samples.size());
  face_first_.assign(mesh.face_capacity(), kNoPoint);
  parked_point_.assign(mesh.vertex_capacity(), kNoPoint);
  sample_vertex_.clear();
  sample_vertex_.reserve(samples.size());
  for (const SurfaceSample& s : samples) {
    const auto id = uint32_t(points_.size());
    points_.push_back({s.position, 0.0, s.face, kNoPoint});
    sample_vertex_.push_back(s.vertex);
    if (scalar_.enabled()) scalar_.add_point(mesh, s.face, s.position);
    if (s.vertex != kNoId) {
      parked_point_[s.vertex] = id;
    } else {
      points_[id].next = face_first_[s.face];
      face_first_[s.face] = id;
    }
  }
}

void EnergyPriority::gather_face(FaceId f, int home) const {
  for (uint32_t id = face_first_[f]; id != kNoPoint; id = points_[id].next) {
    star_points_.push_back(id);
    star_homes_.push_back(home);
  }
}

void EnergyPriority::unpark(VertexId v) {
  const uint32_t id = parked_point_[v];
  if (id == kNoPoint) return;
  parked_point_[v] = kNoPoint;
  star_points_.push_back(id);
}

EnergyPriority::Fit EnergyPriority::project_points(const std::vector<uint32_t>& ids,
                                                   const std::vector<int>& homes, const Vec3& v,
                                                   std::vector<Projected>* where) const {
  Fit fit;
  if (where) where->resize(ids.size());
  prepared_.resize(star_.size());
  prepared_ready_.assign(star_.size(), 0);
  for (size_t i = 0; i < ids.size(); ++i) {
    const Vec3& x = points_[ids[i]].position;
    // A point moves at most one face along the fan per projection: its face's image and the
    // two faces beside it. (The performed collapse projects onto the whole star.)
    Projection best;
    best.distance_sq = std::numeric_limits<double>::infinity();
    int best_j = 0;
    auto consider = [&](int j) {
      if (!prepared_ready_[j]) {
        prepared_[j] = PreparedTriangle(v, star_[j].p1, star_[j].p2);
        prepared_ready_[j] = 1;
      }
      const Projection p = prepared_[j].project(x);
      if (p.distance_sq < best.distance_sq) best = p, best_j = j;
    };
    const int home = homes[i];
    if (home < 0) {
      // The sample of a (b), at a's old position: v moved away from it, towards the other
      // end, so it lies over the faces that were a's (b's).
      const bool a_side = home == -1;
      const int begin = a_side ? 0 : a_side_faces_,
                end = a_side ? a_side_faces_ : int(star_.size());
      for (int j = begin; j < end; ++j) consider(j);
      if (begin == end)
        for (int j = 0; j < int(star_.size()); ++j) consider(j);
    } else {
      consider(home);
      if (star_[home].next >= 0) consider(star_[home].next);
      if (star_[home].previous >= 0) consider(star_[home].previous);
    }
    const StarFace* best_face = &star_[best_j];
    if (where) (*where)[i] = {best_j, best.bary};
    fit.distance_sq += best.distance_sq;
    fit.max_distance_sq = std::max(fit.max_distance_sq, best.distance_sq);
    const double b0 = best.bary[0];
    fit.a += b0 * b0;
    const Vec3 rest = add(scale(best_face->p1, best.bary[1]), scale(best_face->p2, best.bary[2]));
    fit.b = add(fit.b, scale(sub(x, rest), b0));
  }
  return fit;
}

double EnergyPriority::spring_energy_after(const Vec3& v) const {
  double sum = 0;
  for (const StarFace& f : star_) sum += half_edges_sq(v, f.p1, f.p2);
  return sum;
}

bool EnergyPriority::folds(const Vec3& v) const {
  for (const StarFace& f : star_)
    if (face_folds(f.before, f.p1, f.p2, v, f.p1, f.p2)) return true;
  return false;
}

bool EnergyPriority::evaluate(const CollapseMesh& mesh, VertexId a, VertexId b,
                              CollapseCandidate& out) const {
  const bool locked_a = !locked_.empty() && locked_[a];
  const bool locked_b = !locked_.empty() && locked_[b];
  if (locked_a && locked_b) return false;
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
  out.vs = keep_b ? b : a;
  out.vt = keep_b ? a : b;
  const Vec3& pa = mesh.position(a);
  const Vec3& pb = mesh.position(b);

  // The star: every face around a or b; after the collapse those without both ends remain,
  // with the moving corner first. Points of the two faces that disappear are homed next to
  // their apex once the fan is known.
  star_.clear();
  star_points_.clear();
  star_homes_.clear();
  std::array<VertexId, 2> edge_apexes{kNoId, kNoId};
  int edge_faces = 0;
  joined_count_ = 0;
  double spring_before = 0;
  for (VertexId end : {a, b}) {
    if (end == b) a_side_faces_ = int(star_.size());
    const VertexId other = end == a ? b : a;
    for (FaceId f : mesh.faces_of(end)) {
      const Triangle& t = mesh.face(f);
      const int k = corner_of(t, end);
      const int other_corner = corner_of(t, other);
      if (end == b && other_corner >= 0) continue;  // seen from a
      const Vec3& p0 = mesh.position(end);
      const Vec3& p1 = mesh.position(t[(k + 1) % 3]);
      const Vec3& p2 = mesh.position(t[(k + 2) % 3]);
      spring_before += half_edges_sq(p0, p1, p2);
      if (other_corner >= 0) {
        if (edge_faces < 2) {
          edge_apexes[edge_faces] = t[3 - k - other_corner];
          if (scalar_.enabled()) {
            const auto& w = mesh.corner_wedges(f);
            joined_[joined_count_++] = {w[k], w[other_corner]};
          }
          gather_face(f, -2 - edge_faces);
          ++edge_faces;
        }
      } else {
        star_.push_back({p1, p2, p0, t[(k + 1) % 3], t[(k + 2) % 3]});
        if (scalar_.enabled()) {
          const auto& w = mesh.corner_wedges(f);
          star_.back().wedges = {w[k], w[(k + 1) % 3], w[(k + 2) % 3]};
        }
        gather_face(f, int(star_.size()) - 1);
      }
    }
  }
  if (star_.empty()) return false;
  // The fan around the moved vertex, and homes for the points of the two removed faces.
  std::array<int, 2> apex_home{0, 0};
  double parked_around = 0;
  for (int j = 0; j < int(star_.size()); ++j) {
    StarFace& face = star_[j];
    for (int k = 0; k < int(star_.size()); ++k) {
      if (star_[k].id1 == face.id2) face.next = k;
      if (star_[k].id2 == face.id1) face.previous = k;
    }
    for (int e = 0; e < edge_faces; ++e)
      if (face.id1 == edge_apexes[e] || face.id2 == edge_apexes[e]) apex_home[e] = j;
    // A neighbour's parked sample sits on the star's rim: half of it counts as the star's.
    if (parked_point_[face.id1] != kNoPoint) parked_around += 0.5;
  }
  for (int& home : star_homes_)
    if (home < 0) home = apex_home[-2 - home];
  // The samples of a and b themselves, where they still are.
  for (VertexId end : {a, b})
    if (parked_point_[end] != kNoPoint) {
      star_points_.push_back(parked_point_[end]);
      star_homes_.push_back(end == a ? -1 : -2);
    }
  const double points_around = double(star_points_.size()) + parked_around;

  // The points the placement is optimised on: all of them, or an evenly strided subset
  // standing for all. (The cost is then measured on all of them at the chosen placement: a
  // cost estimated on a subset is noisy, and the queue, which picks minima, would pick the
  // lucky draws; that once grew vertices of valence 40 around point-rich stars.)
  const size_t total = star_points_.size();
  const size_t cap = std::max<uint32_t>(1, options_.max_points_per_evaluation);
  evaluated_.clear();
  evaluated_homes_.clear();
  if (total <= cap) {
    evaluated_ = star_points_;
    evaluated_homes_ = star_homes_;
  } else {
    for (size_t i = 0; i < cap; ++i) {
      evaluated_.push_back(star_points_[(i * total) / cap]);
      evaluated_homes_.push_back(star_homes_[(i * total) / cap]);
    }
  }
  curves_.gather(a, b, mesh);
  const double curve_before = curves_.gathered_distance_sq();
  const double weight = evaluated_.empty() ? 0.0 : double(total) / double(evaluated_.size());
  double distance_before = 0;
  for (uint32_t id : evaluated_) distance_before += points_[id].distance_sq;
  distance_before *= weight;

  const double kappa = spring_constant(points_around / double(star_.size()));
  Vec3 spring_pull{};  // kappa/2 * sum (p1 + p2): the springs' part of the normal equations
  for (const StarFace& f : star_) spring_pull = add(spring_pull, add(f.p1, f.p2));
  spring_pull = scale(spring_pull, 0.5 * kappa);
  const double spring_weight = kappa * double(star_.size());

  struct Placement {
    Vec3 v;
    double energy;
    double max_distance_sq;
    double curve_distance_sq;
    double spring;  // kappa * E_spring after the collapse
    size_t index;   // into placement_projections_
  };
  std::array<Placement, 16> placements;
  size_t placed = 0;
  SharpCurves::Fit curve_fit;
  // With E_scalar and every point evaluated, each placement keeps its projections, so that
  // the chosen one's need not be computed again.
  const bool keep_projections = scalar_.enabled() && evaluated_.size() == total;
  auto measure = [&](const Vec3& v, Fit& fit) {
    fit = project_points(
        evaluated_, evaluated_homes_, v,
        keep_projections && placed < placements.size() ? &placement_projections_[placed] : nullptr);
    curve_fit = curves_.gathered() ? curves_.project(v) : SharpCurves::Fit{};
    const double spring = kappa * spring_energy_after(v);
    const double energy = weight * fit.distance_sq + curve_fit.distance_sq + spring;
    if (placed < placements.size()) {
      placements[placed] = {v,
                            energy,
                            std::max(fit.max_distance_sq, curve_fit.max_distance_sq),
                            curve_fit.distance_sq,
                            spring,
                            placed};
      ++placed;
    }
  };
  auto solve = [&](const Fit& fit, const Vec3& from) -> Vec3 {
    const double denominator = weight * fit.a + curve_fit.a + spring_weight;
    if (!(denominator > 0)) return from;
    Vec3 v = scale(add(add(scale(fit.b, weight), curve_fit.b), spring_pull), 1.0 / denominator);
    if (boundary_a && boundary_b && curves_.sample_count() == 0) {
      // Without curve samples (discontinuities off), a boundary edge keeps its vertex on the
      // segment, so that the boundary keeps its place (the energy is isotropic in v, so the
      // constrained optimum is the projection).
      v = add(pa, scale(sub(pb, pa), project_on_segment(v, pa, pb).t));
    }
    return rounded(v, options_.round_to_float);
  };

  Fit fit;
  if (fixed) {
    measure(mesh.position(out.vs), fit);
  } else {
    const Vec3 mid = rounded(scale(add(pa, pb), 0.5), options_.round_to_float);
    for (const Vec3& start : {pa, pb, mid}) {
      Vec3 v = start;
      measure(v, fit);
      for (int i = 0; i < options_.solves_per_start; ++i) {
        v = solve(fit, v);
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
  out.cost = chosen->energy - distance_before - curve_before - kappa * spring_before;
  out.error = std::sqrt(chosen->max_distance_sq);
  if (keep_projections) projected_.swap(placement_projections_[chosen->index]);
  if (evaluated_.size() < total) {
    const Fit all = project_points(star_points_, star_homes_, chosen->v,
                                   scalar_.enabled() ? &projected_ : nullptr);
    double all_before = 0;
    for (uint32_t id : star_points_) all_before += points_[id].distance_sq;
    out.cost = all.distance_sq - all_before + chosen->curve_distance_sq - curve_before +
               chosen->spring - kappa * spring_before;
    out.error = std::sqrt(std::max(all.max_distance_sq, chosen->max_distance_sq));
  }
  if (scalar_.enabled()) out.cost += scalar_change();
  // Penalised, not forbidden (Hoppe 96): such collapses come after every ordinary one.
  if (topology) out.cost += topology_penalty_;
  return std::isfinite(out.cost);
}

// The change of E_scalar over the star's points, projected as in projected_, with the
// wedges of the moving vertex at their best values.
double EnergyPriority::scalar_change() const {
  scalar_.begin_star(joined_, joined_count_);
  for (StarFace& face : star_) face.group = scalar_.group_of(face.wedges[0]);
  double before = 0;
  for (size_t i = 0; i < star_points_.size(); ++i) {
    const uint32_t id = star_points_[i];
    const Projected& p = projected_[i];
    const StarFace& face = star_[p.face];
    scalar_.add(face.group, id, p.bary[0], face.wedges[1], p.bary[1], face.wedges[2], p.bary[2]);
    before += scalar_.residual(id);
  }
  return scalar_.star_energy() - before;
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
  for (size_t i = 0; i < star_points_.size(); ++i) {
    const FaceId f = moved_faces_[i];
    const int k = corner_of(mesh.face(f), done.vs);
    const auto& b = moved_bary_[i];
    const auto w = corners(f, k);
    scalar_.add(scalar_.group_of(w[0]), star_points_[i], b[k], w[1], b[(k + 1) % 3], w[2],
                b[(k + 2) % 3]);
  }
  scalar_.apply(done.changed_wedges, done.changed_values);
  for (size_t i = 0; i < star_points_.size(); ++i) {
    const FaceId f = moved_faces_[i];
    scalar_.set_residual(
        star_points_[i],
        scalar_.residual_against(star_points_[i], mesh.corner_wedges(f), moved_bary_[i]));
  }
}

void EnergyPriority::collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                               const EdgeFaces& edge) {
  // Every point of the old star goes to its closest face of the new one; so do the samples
  // of vt (removed) and of vs if it moved.
  star_points_.clear();
  auto take = [&](FaceId f) {
    for (uint32_t id = face_first_[f]; id != kNoPoint; id = points_[id].next)
      star_points_.push_back(id);
    face_first_[f] = kNoPoint;
  };
  if (edge.left != kNoId) take(edge.left);
  if (edge.right != kNoId) take(edge.right);
  const auto& faces = mesh.faces_of(done.vs);
  for (FaceId f : faces) take(f);
  unpark(done.vt);
  const uint32_t vs_sample = parked_point_[done.vs];
  // vs's own sample stays exact while vs stays put, unless E_scalar gives its wedges new
  // values.
  if (vs_sample != kNoPoint && (points_[vs_sample].position != done.position || scalar_.enabled()))
    unpark(done.vs);
  double max_distance_sq = curves_.collapsed(done.vs, done.vt, mesh);
  if (faces.empty()) return;
  moved_faces_.clear();
  moved_bary_.clear();
  for (uint32_t id : star_points_) {
    Point& point = points_[id];
    Projection best;
    best.distance_sq = std::numeric_limits<double>::infinity();
    FaceId best_face = faces[0];
    double best_score = std::numeric_limits<double>::infinity();
    for (FaceId f : faces) {
      const Triangle& t = mesh.face(f);
      const Projection p = project_on_triangle(point.position, mesh.position(t[0]),
                                               mesh.position(t[1]), mesh.position(t[2]));
      // With E_scalar a point goes where its whole energy is least: a point on a seam is as
      // close to the faces of both sides and belongs to the side whose attributes it has.
      const double score =
          scalar_.enabled()
              ? p.distance_sq + scalar_.residual_against(id, mesh.corner_wedges(f), p.bary)
              : p.distance_sq;
      if (score < best_score) best_score = score, best = p, best_face = f;
    }
    moved_faces_.push_back(best_face);
    moved_bary_.push_back(best.bary);
    point.distance_sq = best.distance_sq;
    point.face = best_face;
    point.next = face_first_[best_face];
    face_first_[best_face] = id;
    max_distance_sq = std::max(max_distance_sq, best.distance_sq);
  }
  if (scalar_.enabled()) update_attributes(mesh, done, edge);
  // The exact largest distance of the star's points, where the evaluation may have looked at
  // a subset.
  done.error = std::sqrt(max_distance_sq);
}

}  // namespace parapm
