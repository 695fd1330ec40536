#include "simplify/energy_evaluator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>

#include <Eigen/Dense>

#include "simplify/energy_priority.h"
#include "simplify/face_fold.h"
#include "simplify/point_projection.h"
#include "simplify/sample_thinning.h"
#include "simplify/vec_math.h"

namespace parapm {
namespace {

// Whether triangle (q0, q1, q2), of normal n (|n|^2 = n_sq), is wide enough to have a plane:
// a thinner one is measured exactly, point by point.
bool has_plane(double n_sq, const Vec3& q0, const Vec3& q1, const Vec3& q2) {
  const Vec3 e1 = sub(q1, q0), e2 = sub(q2, q0);
  return n_sq > 1e-12 * dot(e1, e1) * dot(e2, e2) && n_sq > 0;
}

// Whether two faces' normals (any length) are parallel within about a degree.
bool in_one_plane(const Vec3& n, const Vec3& m) {
  const double c = dot(n, m);
  return c > 0 && c * c > 0.9997 * dot(n, n) * dot(m, m);
}

Vec3 rounded(Vec3 v, bool to_float) {
  if (to_float)
    for (double& c : v) c = round_to_float(c);
  return v;
}

}  // namespace

void EnergyEvaluator::reset(size_t face_capacity) {
  released_capacity_ = 0;
  // Zeroed pages, given memory as faces are first costed (most of a master's never are).
  moments_.assign_zeroed(face_capacity);
  moments_ready_.assign_zeroed(face_capacity);
  own_.assign_zeroed(face_capacity);
  max_distance_sq_.assign_zeroed(face_capacity);
}

double EnergyEvaluator::corners_moved(FaceId f) {
  if (released_capacity_) {
    double max_distance_sq = 0;
    for (const FacePoint& p : module_.face_points_[f])
      max_distance_sq = std::max(max_distance_sq, p.distance_sq);
    return max_distance_sq;
  }
  moments_of(f);
  moments_ready_[f] = 1;
  return max_distance_sq_[f];
}

void EnergyEvaluator::extend(FaceId f, size_t added) {
  if (moments_ready_.empty()) return;
  if (!moments_ready_[f]) {
    moments_of(f);
    return;
  }
  const std::vector<FacePoint>& points = module_.face_points_[f];
  PointMoments& m = moments_[f];
  double& max_distance_sq = max_distance_sq_[f];
  for (size_t i = points.size() - added; i < points.size(); ++i) {
    m.add(points[i].position);
    max_distance_sq = std::max(max_distance_sq, points[i].distance_sq);
  }
  moments_ready_[f] = 1;  // (its own error, of the corners as they were, is dropped)
}

void EnergyEvaluator::release() {
  if (released_capacity_ || moments_.empty()) return;
  released_capacity_ = moments_.size();
  moments_.clear();
  moments_ready_.clear();
  own_.clear();
  max_distance_sq_.clear();
}

bool EnergyEvaluator::evaluate(const CollapseMesh& mesh, VertexId a, VertexId b,
                               CollapseCandidate& out, Costing costing, EnergySeam seam) {
  if (released_capacity_) reset(released_capacity_);
  ++costings_;
  const Survivor survivor = choose_survivor(mesh, a, b, seam.keep);
  if (!survivor.possible) return false;
  out.vs = survivor.keep_b ? b : a;
  out.vt = survivor.keep_b ? a : b;
  StarSums sums = gather_star(mesh, a, b);
  if (scratch_.star.empty())  // no face left around either end: a component's last faces
    return module_.options_.components_may_vanish &&
           evaluate_removal(mesh, a, b, survivor, seam.at, out);
  const StarPoints points = gather_star_points(mesh, link_fan(sums, a, b));
  const Before before = energy_before(mesh, a, b, points.by_moments);
  Placing placing;
  placing.by_moments = points.by_moments;
  placing.keep_projections = module_.scalar_.enabled() && !points.by_moments;
  placing.boundary_edge = survivor.boundary_a && survivor.boundary_b;
  placing.springs = springs_of(points.points_around);
  placing.pa = mesh.position(a);
  placing.pb = mesh.position(b);
  set_star_terms(sums, points.points_around);
  place(mesh, out, survivor, placing, costing, seam.at);
  const Placement& chosen = choose_placement();
  out.position = chosen.v;
  out.cost = chosen.energy - before.distance_sq - before.curves_sq;
  out.error = std::sqrt(chosen.max_distance_sq);
  if (points.by_moments) out.cost += moment_rim_change(mesh, chosen.v, points.reprojected);
  if (module_.scalar_.enabled()) out.cost += attribute_change(placing, chosen);
  // Penalised, not forbidden (Hoppe 96), at a price per point of the star.
  if (survivor.topology) out.cost += module_.topology_price_ * std::max(1.0, points.points_around);
  return std::isfinite(out.cost);
}

bool EnergyEvaluator::evaluate_removal(const CollapseMesh& mesh, VertexId a, VertexId b,
                                       const Survivor& survivor, const Vec3* at,
                                       CollapseCandidate& out) {
  // The points: those of the faces removed and the samples still parked at a and b.
  double before = 0;
  Vec3 sum{};
  std::vector<Vec3>& points = scratch_.removal_points;
  points.clear();
  for (FaceId f : mesh.faces_of(a))
    for (const FacePoint& p : module_.face_points_[f]) {
      points.push_back(p.position);
      before += p.distance_sq;
    }
  for (VertexId end : {a, b})
    if (module_.parked_point_[end] != EnergyPriority::kNoPoint)
      points.push_back(module_.positions_[module_.parked_point_[end]]);
  for (const Vec3& x : points) sum = add(sum, x);
  const SharpCurves& curves = module_.curves_;
  SharpCurves::Gathered& gathered = scratch_.curve_samples;
  curves.gather(a, b, mesh, module_.options_.max_sampled_points, gathered);
  before += curves.distance_sq(gathered);

  // Each point at its squared distance to v; the samples at theirs to the segments left.
  struct Priced {
    double energy, max_distance_sq;
  };
  auto price = [&](const Vec3& v, SharpCurves::Fit* curve_fit) {
    Priced priced{0, 0};
    for (const Vec3& x : points) {
      const Vec3 d = sub(x, v);
      priced.energy += dot(d, d);
      priced.max_distance_sq = std::max(priced.max_distance_sq, dot(d, d));
    }
    const SharpCurves::Fit fit = gathered.size() ? curves.project(gathered, v) : SharpCurves::Fit{};
    priced.energy += fit.distance_sq;
    priced.max_distance_sq = std::max(priced.max_distance_sq, fit.max_distance_sq);
    if (curve_fit) *curve_fit = fit;
    return priced;
  };
  const bool round = module_.options_.round_to_float;
  Vec3 v = at ? *at : mesh.position(out.vs);
  Priced best = price(v, nullptr);
  if (!survivor.fixed && !at) {
    // From the points' centroid, one least-squares step with the curves' model there.
    const Vec3 centroid = points.empty() ? scale(add(mesh.position(a), mesh.position(b)), 0.5)
                                         : scale(sum, 1.0 / double(points.size()));
    SharpCurves::Fit curve_fit;
    const Vec3 start = rounded(centroid, round);
    Priced at_start = price(start, &curve_fit);
    const double weight = double(points.size()) + curve_fit.a;
    const Vec3 solved =
        weight > 0 ? rounded(scale(add(sum, curve_fit.b), 1.0 / weight), round) : start;
    const Priced at_solved = price(solved, nullptr);
    for (const auto& [place, priced] : {std::pair{start, at_start}, std::pair{solved, at_solved}})
      if (priced.energy < best.energy) v = place, best = priced;
  }
  out.position = v;
  out.cost = best.energy - before;
  out.error = std::sqrt(best.max_distance_sq);
  return std::isfinite(out.cost);
}

EnergyEvaluator::Before EnergyEvaluator::energy_before(const CollapseMesh& mesh, VertexId a,
                                                       VertexId b, bool by_moments) {
  module_.curves_.gather(a, b, mesh, module_.options_.max_sampled_points, scratch_.curve_samples);
  Before before;
  before.curves_sq = module_.curves_.distance_sq(scratch_.curve_samples);
  before.distance_sq = by_moments ? moment_distance_before(mesh) : exact_distance_sq();
  return before;
}

EnergyEvaluator::Springs EnergyEvaluator::springs_of(double points_around) const {
  const double kappa =
      module_.options_.spring_scale * spring_constant(points_around / double(scratch_.star.size()));
  Springs springs;
  for (const StarFace& f : scratch_.star) springs.pull = add(springs.pull, add(f.p1, f.p2));
  springs.pull = scale(springs.pull, 0.5 * kappa);
  springs.weight = kappa * double(scratch_.star.size());
  return springs;
}

void EnergyEvaluator::place(const CollapseMesh& mesh, const CollapseCandidate& out,
                            const Survivor& survivor, const Placing& placing, Costing costing,
                            const Vec3* at) {
  scratch_.placed = 0;
  Fit fit;
  if (survivor.fixed || at) {
    measure(placing, at ? *at : mesh.position(out.vs), fit);
    return;
  }
  const Vec3 mid =
      rounded(scale(add(placing.pa, placing.pb), 0.5), module_.options_.round_to_float);
  // A queue key starts from fewer places than the performed collapse, which tries all three:
  // a young star projected point by point (an end still holds its own sample, which is on
  // the input surface) from the two ends, a star costed by moments from the midpoint only
  // (its solve is the dear part). A projected star's key is still an upper bound of the cost
  // measured at the top, looser where the midpoint's start would win: such edges come a little
  // later. Chosen by measurement: faster, and no level worse (decisions/notebook-2026-11.md,
  // "Queue keys from fewer starts").
  std::array<Vec3, 3> starts{placing.pa, placing.pb, mid};
  std::span<const Vec3> tried(starts);
  if (costing != Costing::kPerform) {  // (kEstimate: the same key)
    if (placing.by_moments) {
      tried = tried.subspan(2);
    } else if (!scratch_.parked_ends.empty()) {
      tried = tried.first(2);
    }
  }
  auto& placements = scratch_.placements;
  for (const Vec3& start : tried) {
    Vec3 v = start;
    measure(placing, v, fit);
    for (int i = 0; i < module_.options_.solves_per_start; ++i) {
      v = solve(placing, fit, v);
      if (costing != Costing::kPerform && i + 1 == module_.options_.solves_per_start) {
        // A queue key: the last solve is costed on the model it minimised, not measured
        // again, which halves the projections. For projected points the model is an upper
        // bound of the measured energy (each point's barycentric coordinates put it on a
        // face of the new star), so the key errs towards later, never earlier; the moments'
        // model is the reweighted planes'. The collapse is measured when it is performed.
        if (scratch_.placed < placements.size()) {
          const double distance = placing.by_moments ? scratch_.plane_model.at(v) : fit.model_at(v);
          double energy = distance + scratch_.curve_fit.model_at(v);
          if (module_.star_terms_on_) energy += scratch_.terms.evaluate(sub(v, scratch_.origin));
          placements[scratch_.placed++] = {v, energy, 0, kNotProjected};
        }
        break;
      }
      measure(placing, v, fit);
    }
  }
}

// The energy with the moving vertex at v, recorded as a placement (the first 16 of a costing).
// With E_scalar and every point projected, each placement keeps its projections, so that the
// chosen one's need not be computed again.
void EnergyEvaluator::measure(const Placing& placing, const Vec3& v, Fit& fit) {
  auto& placements = scratch_.placements;
  size_t& placed = scratch_.placed;
  if (placing.by_moments) {
    fit = Fit{};
    fit.distance_sq = moment_distance_after(v);
  } else {
    fit = project_points(scratch_.points, scratch_.homes, v,
                         placing.keep_projections && placed < placements.size()
                             ? &scratch_.placement_projections[placed]
                             : nullptr);
  }
  SharpCurves::Fit& curve_fit = scratch_.curve_fit;
  curve_fit = scratch_.curve_samples.size() ? module_.curves_.project(scratch_.curve_samples, v)
                                            : SharpCurves::Fit{};
  double energy = fit.distance_sq + curve_fit.distance_sq;
  if (module_.star_terms_on_) energy += scratch_.terms.evaluate(sub(v, scratch_.origin));
  if (placed < placements.size()) {
    placements[placed] = {v, energy, std::max(fit.max_distance_sq, curve_fit.max_distance_sq),
                          placed};
    ++placed;
  }
}

// The least-squares solve from `from`, with the springs' and the last measured curves' terms.
Vec3 EnergyEvaluator::solve(const Placing& placing, const Fit& fit, const Vec3& from) {
  const SharpCurves::Fit& curve_fit = scratch_.curve_fit;
  const double iso_a = curve_fit.a + placing.springs.weight;
  const Vec3 iso_b = add(curve_fit.b, placing.springs.pull);
  Vec3 v = placing.by_moments ? moment_solve(from, iso_a, iso_b, &scratch_.plane_model)
                              : projection_solve(fit, iso_a, iso_b, from);
  if (placing.boundary_edge && !module_.curves_.has_samples()) {
    // Without curve samples (discontinuities off), a boundary edge keeps its vertex on the
    // segment, so that the boundary keeps its place (the projection: the constrained
    // optimum of an isotropic energy, near it with the star's terms).
    v = add(placing.pa,
            scale(sub(placing.pb, placing.pa), project_on_segment(v, placing.pa, placing.pb).t));
  }
  return rounded(v, module_.options_.round_to_float);
}

const EnergyEvaluator::Placement& EnergyEvaluator::choose_placement() {
  auto& placements = scratch_.placements;
  std::sort(placements.begin(), placements.begin() + scratch_.placed,
            [](const Placement& x, const Placement& y) { return x.energy < y.energy; });
  for (size_t i = 0; i < scratch_.placed; ++i)
    if (!folds(placements[i].v)) return placements[i];
  return placements[0];
}

// E_scalar counts the star's points; the star's planes stand for star_planes_weight times as
// many between them, which carry attributes too, so the attributes' change is weighted as over
// all of them: else the geometry would outweigh the attributes star_planes_weight times more
// than E_scalar's weight says.
double EnergyEvaluator::attribute_change(const Placing& placing, const Placement& chosen) {
  // E_scalar wants every point's projection at the chosen placement.
  if (placing.keep_projections && chosen.index != kNotProjected) {
    scratch_.projected.swap(scratch_.placement_projections[chosen.index]);
  } else {
    project_points(scratch_.points, scratch_.homes, chosen.v, &scratch_.projected);
  }
  return (1 + module_.options_.star_planes_weight) * scalar_change();
}

EnergyEvaluator::Survivor EnergyEvaluator::choose_survivor(const CollapseMesh& mesh, VertexId a,
                                                           VertexId b, VertexId keep) const {
  // With `keep`, no end is locked.
  const bool locked_a = keep == kNoId && !module_.locked_.empty() && module_.locked_[a];
  const bool locked_b = keep == kNoId && !module_.locked_.empty() && module_.locked_[b];
  if (locked_a && locked_b) return {};
  const bool boundary_a = mesh.is_boundary(a), boundary_b = mesh.is_boundary(b);
  // Discontinuity curves (boundaries, creases, seams): a vertex on a curve does not leave
  // it for an inner vertex, nor a curve's corner or end (not two sharp edges) for a vertex
  // along it; a collapse that changes the curves' topology keeps vs in place and pays.
  const bool curve_a = boundary_a || module_.curves_.on_curve(a);
  const bool curve_b = boundary_b || module_.curves_.on_curve(b);
  const bool corner_a =
      module_.curves_.on_curve(a) && module_.curves_.sharp_neighbors(a).size() != 2;
  const bool corner_b =
      module_.curves_.on_curve(b) && module_.curves_.sharp_neighbors(b).size() != 2;
  const bool topology = module_.curves_.changes_topology(a, b);
  // Which end survives: a locked end, else the end on a curve, else a corner, else the
  // smaller id.
  bool keep_b;
  if (keep != kNoId) {
    keep_b = keep == b;
  } else if (locked_a || locked_b) {
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

void EnergyEvaluator::add_boundary_planes(const CollapseMesh& mesh, const Triangle& t, int k,
                                          const Vec3& n, Quadric& planes) const {
  const VertexId end = t[k];
  const double weight = module_.options_.star_planes_weight;
  if (!mesh.is_boundary(end) || weight <= 0) return;
  const double n_length = length(n);
  for (const auto& [from, to] : {std::pair{end, t[(k + 1) % 3]}, std::pair{t[(k + 2) % 3], end}}) {
    if (!mesh.is_boundary(from == end ? to : from)) continue;
    if (mesh.edge_faces(to, from).left != kNoId) continue;  // an inner edge
    const Vec3 e = sub(mesh.position(to), mesh.position(from));
    const Vec3 side = cross(e, n);
    const double side_length = length(side);
    if (side_length == 0 || n_length == 0) continue;
    const Vec3 m = scale(side, 1 / side_length);
    const double offset = dot(m, sub(mesh.position(from), scratch_.origin));
    planes += Quadric::from_plane(m, -offset, dot(e, e) / weight);
  }
}

EnergyEvaluator::StarSums EnergyEvaluator::gather_star(const CollapseMesh& mesh, VertexId a,
                                                       VertexId b) {
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
      if (module_.star_terms_on_) {
        const Vec3 n = triangle_normal(p0, p1, p2);
        const double n_length = length(n);
        const double offset = dot(n, sub(p0, scratch_.origin));
        normals = add(normals, n);
        offsets += offset;
        area2 += n_length;
        if (n_length > 0) {
          star_planes += Quadric::from_plane(scale(n, 1 / n_length), -offset / n_length, n_length);
          add_boundary_planes(mesh, t, k, n, star_planes);
        }
      }
      if (other_corner >= 0) {
        if (edge_faces < 2) {
          edge_apexes[edge_faces] = t[3 - k - other_corner];
          if (module_.scalar_.enabled()) {
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
        if (module_.scalar_.enabled()) {
          const auto& w = mesh.corner_wedges(f);
          scratch_.star.back().wedges = {w[k], w[(k + 1) % 3], w[(k + 2) % 3]};
        }
        scratch_.lists.push_back({f, int(scratch_.star.size()) - 1});
      }
    }
  }
  return {star_planes, normals, offsets, area2, edge_apexes, edge_faces};
}

double EnergyEvaluator::link_fan(const StarSums& sums, VertexId a, VertexId b) {
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
    if (module_.parked_point_[face.id1] != EnergyPriority::kNoPoint) parked_around += 0.5;
  }
  scratch_.edge_face_homes = apex_home;
  // The samples of a and b themselves, where they still are.
  scratch_.parked_ends.clear();
  scratch_.parked_end_homes.clear();
  for (VertexId end : {a, b})
    if (module_.parked_point_[end] != EnergyPriority::kNoPoint) {
      scratch_.parked_ends.push_back(module_.parked(module_.parked_point_[end]));
      scratch_.parked_end_homes.push_back(end == a ? -1 : -2);
    }
  return parked_around;
}

EnergyEvaluator::StarPoints EnergyEvaluator::gather_star_points(const CollapseMesh& mesh,
                                                                double parked_around) {
  // How many points the star holds: the faces' counts are their moments' (kept per face).
  size_t in_faces = 0;
  for (const auto& list : scratch_.lists) in_faces += module_.face_points_[list.first].size();
  const size_t total = in_faces + scratch_.parked_ends.size();
  const double points_around = double(total) + parked_around;
  // A star with more points than cap is placed and costed on its faces' point moments, in
  // O(faces) whatever its points (moment_solve, moment_distance_after): late collapses cover
  // hundreds of points. A smaller one projects each point, exactly. With E_scalar the points
  // are gathered either way: the attributes need where each one lands.
  const size_t cap = std::max<uint32_t>(1, module_.options_.max_points_per_evaluation);
  const bool by_moments = total > cap;
  scratch_.point_weight = 1;
  const size_t sampled = module_.options_.max_sampled_points;
  auto gather_all = [&] {
    for (const auto& [f, home] : scratch_.lists)
      gather_face(mesh, f, home < 0 ? scratch_.edge_face_homes[-2 - home] : home);
    scratch_.points.insert(scratch_.points.end(), scratch_.parked_ends.begin(),
                           scratch_.parked_ends.end());
    scratch_.homes.insert(scratch_.homes.end(), scratch_.parked_end_homes.begin(),
                          scratch_.parked_end_homes.end());
  };
  if (!by_moments || (module_.scalar_.enabled() && (sampled == 0 || total <= sampled))) {
    gather_all();
  } else if (module_.scalar_.enabled()) {
    // About one point in k stands for k: E_scalar costs each point it sees.
    const size_t stride = (total + sampled - 1) / sampled;
    auto take = [&](const FacePoint& p, int home) {
      if (!kept_when_thinned(module_.point_id_.empty() ? p.id : module_.point_id_[p.id], stride))
        return;
      scratch_.points.push_back(p);
      scratch_.homes.push_back(home);
    };
    for (const auto& [f, home] : scratch_.lists)
      for (const FacePoint& p : module_.face_points_[f])
        take(p, home < 0 ? scratch_.edge_face_homes[-2 - home] : home);
    for (size_t i = 0; i < scratch_.parked_ends.size(); ++i)
      take(scratch_.parked_ends[i], scratch_.parked_end_homes[i]);
    if (scratch_.points.empty()) {
      gather_all();
    } else {
      scratch_.point_weight = double(total) / double(scratch_.points.size());
    }
  }
  return {by_moments, points_around, module_.reprojects_every_point(in_faces)};
}

void EnergyEvaluator::set_star_terms(StarSums& sums, double points_around) {
  if (module_.star_terms_on_) {
    // Points spread at density rho = points / area over a face of the star, v moving by h off
    // its plane, are moved by h times their barycentric coordinate of v: rho area h^2 / 6 in
    // all. The volume's change over the star's area is a mean displacement of
    // (sums.normals.v - sums.offsets) / (3 sums.area2), for all the star's points.
    const double points = std::max(1.0, points_around);
    scratch_.terms = Quadric{};
    if (sums.area2 > 0 && module_.options_.star_planes_weight > 0) {
      sums.planes *= module_.options_.star_planes_weight * points / (6 * sums.area2);
      scratch_.terms += sums.planes;
    }
    const double normals_length = length(sums.normals);
    if (sums.area2 > 0 && normals_length > 0 && module_.options_.volume_weight > 0) {
      Quadric volume =
          Quadric::from_plane(scale(sums.normals, 1 / normals_length),
                              -sums.offsets / normals_length, normals_length * normals_length);
      volume *= module_.options_.volume_weight * points / (9 * sums.area2 * sums.area2);
      scratch_.terms += volume;
    }
  }
}

void EnergyEvaluator::gather_face(const CollapseMesh& mesh, FaceId f, int home) {
  const auto& list = module_.face_points_[f];
  const size_t first = scratch_.points.size();
  scratch_.points.insert(scratch_.points.end(), list.begin(), list.end());
  scratch_.homes.insert(scratch_.homes.end(), list.size(), home);
  // Rare, and the star is small (costed point by point). The drift's bound would do for an
  // error but not for the energy before the collapse: inflated, it would make every collapse
  // that measures these points again look cheap.
  if (module_.drift_[f] != 0) {
    const Triangle& t = mesh.face(f);
    const Vec3 &q0 = mesh.position(t[0]), &q1 = mesh.position(t[1]), &q2 = mesh.position(t[2]);
    for (size_t i = first; i < scratch_.points.size(); ++i)
      scratch_.points[i].distance_sq =
          project_on_triangle(scratch_.points[i].position, q0, q1, q2).distance_sq;
  }
}

PointMoments EnergyEvaluator::moments_of(FaceId f) {
  const EnergyEvaluator& caches = shared_ ? *shared_ : *this;
  if (caches.moments_ready_[f]) return caches.moments_[f];
  PointMoments m;
  double max_distance_sq = 0;
  for (const FacePoint& p : module_.face_points_[f]) {
    m.add(p.position);
    max_distance_sq = std::max(max_distance_sq, p.distance_sq);
  }
  if (!shared_) {
    moments_[f] = m;
    max_distance_sq_[f] = max_distance_sq;
    moments_ready_[f] = 1;
  }
  return m;
}

EnergyEvaluator::OwnError EnergyEvaluator::own_error_of(const CollapseMesh& mesh, FaceId f) {
  const EnergyEvaluator& caches = shared_ ? *shared_ : *this;
  if (caches.moments_ready_[f] == 2) return caches.own_[f];
  const Triangle& t = mesh.face(f);
  const Vec3 &q0 = mesh.position(t[0]), &q1 = mesh.position(t[1]), &q2 = mesh.position(t[2]);
  const OwnError own{plane_distance_sq(f, q0, q1, q2), rim_sq(f, q0, q1, q2, RimAround::kOwn)};
  if (!shared_) {
    own_[f] = own;
    moments_ready_[f] = 2;
  }
  return own;
}

void EnergyEvaluator::fill_for_views(const CollapseMesh& mesh, std::span<const FaceId> faces) {
  if (released_capacity_) reset(released_capacity_);
  for (const FaceId f : faces) own_error_of(mesh, f);
}

// The squared distances of face f's points to the plane of (q0, q1, q2); to the triangle
// itself when it is too thin to have a plane.
double EnergyEvaluator::plane_distance_sq(FaceId f, const Vec3& q0, const Vec3& q1,
                                          const Vec3& q2) {
  const PointMoments& m = moments_of(f);
  if (m.count == 0) return 0;
  const Vec3 n = triangle_normal(q0, q1, q2);
  const double n_sq = dot(n, n);
  if (has_plane(n_sq, q0, q1, q2)) return m.plane_distance_sq(q0, scale(n, 1.0 / std::sqrt(n_sq)));
  double sum = 0;
  for (const FacePoint& p : module_.face_points_[f])
    sum += project_on_triangle(p.position, q0, q1, q2).distance_sq;
  return sum;
}

// A lower bound of how far face f's points lie outside the triangle (q0, q1, q2) within its
// plane, which the plane distances leave out: count x (the mean's in-plane distance)^2, since
// the squared distance to a convex set is convex (Jensen), with the mean also tried on the
// faces `around` it (RimAround), where a point may move. 0 for a thin triangle (measured
// exactly by plane_distance_sq).
double EnergyEvaluator::rim_sq(FaceId f, const Vec3& q0, const Vec3& q1, const Vec3& q2,
                               RimAround around, int star_face, const CollapseMesh* mesh) {
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
  auto try_triangle = [&](const Vec3& t0, const Vec3& t1, const Vec3& t2) {
    if (closest > h_sq)
      closest = std::min(closest, project_on_triangle(m.mean, t0, t1, t2).distance_sq);
  };
  const auto& star = scratch_.star;
  switch (around) {
    case RimAround::kOwn:
      break;
    case RimAround::kBeside:  // q0 is the moving vertex after the collapse
      for (const int j : {star[star_face].next, star[star_face].previous})
        if (j >= 0) try_triangle(q0, star[j].p1, star[j].p2);
      break;
    case RimAround::kStarAfter:
      for (size_t j = 0; j < star.size(); ++j)
        if (int(j) != star_face) try_triangle(q0, star[j].p1, star[j].p2);
      break;
    case RimAround::kStarBefore:
      for (const StarFace& face : star) try_triangle(face.before, face.p1, face.p2);
      for (const FaceId removed : scratch_.edge_faces)
        if (removed != kNoId) {
          const Triangle& t = mesh->face(removed);
          try_triangle(mesh->position(t[0]), mesh->position(t[1]), mesh->position(t[2]));
        }
      break;
  }
  return closest > h_sq ? m.count * (closest - h_sq) : 0;
}

// The change of the rim bound (rim_sq) over the star when the moving vertex goes to v. Added
// to the cost at the chosen placement only: the placements are compared on the planes.
double EnergyEvaluator::moment_rim_change(const CollapseMesh& mesh, const Vec3& v,
                                          bool reprojected) {
  // A star that is flat, before and after, and whose points the collapse projects again: a
  // point that leaves its face lands on another at no distance, so the mean is tried on the
  // whole star, before and after alike. Else on its own face before, and beside it in the fan
  // after (where a curved star's points may go, and a kept one's stay).
  Vec3 normal{};
  bool flat = reprojected;
  auto same_plane = [&](const Vec3& m) {
    if (dot(normal, normal) == 0) normal = m;
    flat = flat && in_one_plane(normal, m);
  };
  for (const StarFace& face : scratch_.star) {
    if (!flat) break;
    same_plane(triangle_normal(face.before, face.p1, face.p2));
    same_plane(triangle_normal(v, face.p1, face.p2));
  }
  for (const FaceId removed : scratch_.edge_faces)
    if (flat && removed != kNoId) {
      const Triangle& t = mesh.face(removed);
      same_plane(triangle_normal(mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2])));
    }
  auto before = [&](FaceId f) {
    if (!flat) return own_error_of(mesh, f).rim_sq;
    const Triangle& t = mesh.face(f);
    return rim_sq(f, mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]),
                  RimAround::kStarBefore, -1, &mesh);
  };
  const RimAround after = flat ? RimAround::kStarAfter : RimAround::kBeside;
  double change = 0;
  for (size_t j = 0; j < scratch_.star.size(); ++j)
    change += rim_sq(scratch_.star[j].source, v, scratch_.star[j].p1, scratch_.star[j].p2, after,
                     int(j)) -
              before(scratch_.star[j].source);
  for (int e = 0; e < 2; ++e)
    if (const FaceId f = scratch_.edge_faces[e]; f != kNoId) {
      const StarFace& home = scratch_.star[scratch_.edge_face_homes[e]];
      change += rim_sq(f, v, home.p1, home.p2, after, scratch_.edge_face_homes[e]) - before(f);
    }
  return change;
}

// E_dist of a star too rich in points to project each one, in O(faces of the star): each
// face's points are measured against its plane (by their moments), before and after alike, so
// that the error of a point whose closest point is on a face's rim, not inside, is left out of
// both rather than one. Only the samples of a and b (parked, at distance 0 before) are
// projected one by one.
double EnergyEvaluator::moment_distance_before(const CollapseMesh& mesh) {
  double sum = 0;
  for (const StarFace& f : scratch_.star) sum += own_error_of(mesh, f.source).plane_sq;
  for (const FaceId f : scratch_.edge_faces)
    if (f != kNoId) sum += own_error_of(mesh, f).plane_sq;
  return sum;
}

double EnergyEvaluator::moment_distance_after(const Vec3& v) {
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
Vec3 EnergyEvaluator::moment_solve(const Vec3& from, double iso_a, const Vec3& iso_b,
                                   PlaneModel* model) {
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
  if (module_.star_terms_on_) {
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
Vec3 EnergyEvaluator::projection_solve(const Fit& fit, double iso_a, const Vec3& iso_b,
                                       const Vec3& from) const {
  const double diagonal = fit.a + iso_a;
  if (!(diagonal > 0)) return from;
  const Vec3 pull = add(fit.b, iso_b);
  if (module_.star_terms_on_) {
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

double EnergyEvaluator::exact_distance_sq() const {
  double sum = 0;
  for (const FacePoint& p : scratch_.points) sum += p.distance_sq;
  return sum;
}

EnergyEvaluator::Fit EnergyEvaluator::project_points(const std::vector<FacePoint>& points,
                                                     const std::vector<int>& homes, const Vec3& v,
                                                     std::vector<Projected>* where) {
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

bool EnergyEvaluator::folds(const Vec3& v) const {
  for (const StarFace& f : scratch_.star)
    if (face_folds(f.before, f.p1, f.p2, v, f.p1, f.p2)) return true;
  return false;
}

// The change of E_scalar over the star's points, projected as in scratch_.projected, with the
// wedges of the moving vertex at their best values.
double EnergyEvaluator::scalar_change() {
  module_.scalar_.begin_star(scratch_.joined, scratch_.joined_count);
  for (StarFace& face : scratch_.star) face.group = module_.scalar_.group_of(face.wedges[0]);
  double before = 0;
  for (size_t i = 0; i < scratch_.points.size(); ++i) {
    const uint32_t id = scratch_.points[i].id;
    const Projected& p = scratch_.projected[i];
    const StarFace& face = scratch_.star[p.face];
    module_.scalar_.add(face.group, id, p.bary[0], face.wedges[1], p.bary[1], face.wedges[2],
                        p.bary[2]);
    before += module_.scalar_.residual(id);
  }
  return (module_.scalar_.star_energy() - before) * scratch_.point_weight;
}

}  // namespace parapm
