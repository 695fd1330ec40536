#include "simplify/energy_priority.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <span>

#include <Eigen/Dense>

#include "simplify/face_fold.h"
#include "simplify/point_projection.h"
#include "simplify/sample_thinning.h"
#include "simplify/surface_samples.h"
#include "simplify/vec_math.h"
#include "util/error.h"
#include "util/fresh_pages.h"
#include "util/thread_team.h"

namespace parapm {
namespace {

// The longest edge of face f.
double face_size(const CollapseMesh& mesh, FaceId f) {
  const Triangle& t = mesh.face(f);
  double longest_sq = 0;
  for (int k = 0; k < 3; ++k) {
    const Vec3 e = sub(mesh.position(t[(k + 1) % 3]), mesh.position(t[k]));
    longest_sq = std::max(longest_sq, dot(e, e));
  }
  return std::sqrt(longest_sq);
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
  ChunkedLoops plain;
  initialize_in_chunks(mesh, plain);
}

void EnergyPriority::initialize_in_chunks(const CollapseMesh& mesh, ChunkedLoops& loops) {
  initialize_curves(mesh, loops);
  initialize_points(mesh, loops);
}

void EnergyPriority::initialize_curves(const CollapseMesh& mesh, ChunkedLoops& loops) {
  if (options_.discontinuities) {
    curves_.initialize(mesh, options_.sharp, loops);
  } else {
    curves_ = SharpCurves{};
    curves_.initialize_empty(mesh);
  }
}

void EnergyPriority::reset_point_lists(const CollapseMesh& mesh, ChunkedLoops& loops) {
  assign_touched(face_points_, mesh.face_capacity(), {}, loops);
  evaluator_.reset(mesh.face_capacity());
  assign_touched(drift_, mesh.face_capacity(), 0.0, loops);
  assign_touched(parked_point_, mesh.vertex_capacity(), kNoPoint, loops);
}

void EnergyPriority::initialize_points(const CollapseMesh& mesh, ChunkedLoops& loops) {
  const std::vector<SurfaceSample> samples =
      sample_surface(mesh, options_.samples_per_face, options_.seed, loops);
  const double diagonal = diagonal_of(mesh);
  topology_price_ = topology_price(diagonal);

  const bool scalar = mesh.has_wedges() && attributes_.layout.any();
  scalar_.initialize(scalar ? attributes_.layout : AttributeLayout{}, attributes_.values,
                     options_.attribute_weight * diagonal);
  if (scalar_.enabled()) scalar_.add_points(mesh, samples, loops);

  point_id_.clear();
  resize_touched(positions_, samples.size(), loops);
  reset_point_lists(mesh, loops);
  // A point's id is its sample's index. The vertices' samples come first: each is parked at
  // its vertex; the others are listed on their faces, newest first, as collapsed() leaves
  // them (the order of the sums over a face's points is part of the build's arithmetic).
  // Each range of faces lists its own drawn samples.
  size_t parked = 0;
  while (parked < samples.size() && samples[parked].vertex != kNoId) ++parked;
  loops.run(samples.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      positions_[i] = samples[i].position;
      if (i < parked) parked_point_[samples[i].vertex] = uint32_t(i);
    }
  });
  auto face_of = [&](size_t i) { return i < parked ? kNoKey : samples[i].face; };
  const auto points_of_range =
      items_of_ranges(loops, samples.size(), mesh.face_capacity(), face_of);
  loops.run_indexed(mesh.face_capacity(), [&](size_t range, size_t, size_t) {
    const RangeItems points(points_of_range, range, samples.size());
    for (size_t j = points.size(); j-- > 0;) {
      const uint32_t i = points[j];
      if (i < parked) break;
      face_points_[samples[i].face].push_back({samples[i].position, 0.0, i});
    }
  });
}

double EnergyPriority::diagonal_of(const CollapseMesh& mesh) const {
  return options_.reference_diagonal > 0 ? options_.reference_diagonal
                                         : bounding_box(mesh.positions()).diagonal();
}

void EnergyPriority::evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                                   Costing costing) {
  if (!team_ || edges.size() < 2 || scalar_.enabled() ||
      (!team_awake_ && edges.size() < kEdgesWakingTheTeam)) {
    PriorityModule::evaluate_each(mesh, edges, costing);
    return;
  }
  // The faces every costing reads the caches of: those around the edges' ends.
  view_faces_.clear();
  for (const EdgeCosting& e : edges)
    for (const VertexId end : {e.a, e.b})
      view_faces_.insert(view_faces_.end(), mesh.faces_of(end).begin(), mesh.faces_of(end).end());
  std::sort(view_faces_.begin(), view_faces_.end());
  view_faces_.erase(std::unique(view_faces_.begin(), view_faces_.end()), view_faces_.end());
  evaluator_.fill_for_views(mesh, view_faces_);
  while (views_.size() < team_->ranges(edges.size()))
    views_.push_back(std::make_unique<EnergyEvaluator>(*this, evaluator_));
  team_->run_indexed(edges.size(), [&](size_t range, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      EdgeCosting& e = edges[i];
      e.placed = views_[range]->evaluate(mesh, e.a, e.b, e.candidate, costing);
    }
  });
}

uint64_t EnergyPriority::costings() const {
  uint64_t sum = evaluator_.costings();
  for (const auto& view : views_) sum += view->costings();
  return sum;
}

void EnergyPriority::unpark(VertexId v) {
  const uint32_t id = parked_point_[v];
  if (id == kNoPoint) return;
  parked_point_[v] = kNoPoint;
  moved_.sources.push_back({kNoId, -1, false, moved_.count, parked(id)});
  ++moved_.count;
}

void EnergyPriority::take(FaceId f, int home, bool removed) {
  moved_.sources.push_back({f, home, removed, moved_.count, {}});
  moved_.count += face_points_[f].size();
  evaluator_.forget(f);
  drift_[f] = 0;
}

void EnergyPriority::grow_moved_buffers() {
  if (moved_.points.size() >= moved_.count) return;
  // A point moves at most once per collapse: room for them all, the same for every buffer.
  const size_t room = std::max(moved_.count, point_count());
  moved_.points.assign_zeroed(room);
  moved_.homes.assign_zeroed(room);
  moved_.in_fan.assign_zeroed(room);
  moved_.faces.assign_zeroed(room);
  moved_.bary.assign_zeroed(room);
  moved_.by_face.assign_zeroed(room);
}

void EnergyPriority::move_taken_points() {
  grow_moved_buffers();
  for (const Reprojection::Source& source : moved_.sources) {
    if (source.face == kNoId) {
      moved_.points[source.at] = source.sample;
      moved_.homes[source.at] = source.home;
      continue;
    }
    std::vector<FacePoint>& list = face_points_[source.face];
    std::copy(list.begin(), list.end(), &moved_.points[source.at]);
    std::fill_n(&moved_.homes[source.at], list.size(), source.home);
    list.clear();
    if (source.removed) list.shrink_to_fit();
  }
}

double EnergyPriority::list_on_team(
    std::span<const FaceId> faces,
    const std::function<void(size_t i, FacePoint point, int home)>& project) {
  grow_moved_buffers();
  const size_t moving = moved_.count;
  const std::vector<Reprojection::Source>& sources = moved_.sources;
  const size_t fan = faces.size();
  // The points in blocks, each range taking every ranges-th block: the removed faces' points,
  // listed first, cost more to project (their faces are gone) and are spread over the ranges.
  const size_t ranges = team_->ranges(moving);
  const size_t blocks = std::min(moving, kBlocksPerRange * ranges);
  auto block_begin = [&](size_t k) { return moving * k / blocks; };
  auto each_block = [&](const std::function<void(size_t k)>& body) {
    team_->run(ranges, [&](size_t begin, size_t end) {
      for (size_t r = begin; r < end; ++r)
        for (size_t k = r; k < blocks; k += ranges) body(k);
    });
  };
  // Per block and face of the fan: how many of the block's points go to the face, then where
  // the first of them goes in by_face, which holds the points face after face, each face's
  // the last point first (so the last block's first).
  std::vector<size_t>& slots = moved_.slots;
  slots.assign(blocks * fan, 0);
  each_block([&](size_t k) {
    const size_t begin = block_begin(k), end = block_begin(k + 1);
    // Point i is in the last source starting at or before it (a face's list, or a sample).
    auto source =
        std::upper_bound(sources.begin(), sources.end(), begin,
                         [](size_t i, const Reprojection::Source& s) { return i < s.at; });
    size_t* count = &slots[k * fan];
    for (size_t i = begin; i < end; ++i) {
      while (source != sources.end() && source->at <= i) ++source;
      const Reprojection::Source& from = *(source - 1);
      project(i, from.face == kNoId ? from.sample : face_points_[from.face][i - from.at],
              from.home);
      ++count[moved_.in_fan[i]];
    }
  });
  moved_.fan_start.resize(fan + 1);
  size_t at = 0;
  for (size_t j = 0; j < fan; ++j) {
    moved_.fan_start[j] = at;
    for (size_t k = blocks; k-- > 0;) {
      const size_t n = slots[k * fan + j];
      slots[k * fan + j] = at;
      at += n;
    }
  }
  moved_.fan_start[fan] = at;
  moved_.block_max_sq.assign(blocks, 0.0);
  each_block([&](size_t k) {
    size_t* next = &slots[k * fan];
    double largest_sq = 0;
    for (size_t i = block_begin(k + 1); i-- > block_begin(k);) {
      const FacePoint& point = moved_.points[i];
      moved_.by_face[next[moved_.in_fan[i]]++] = point;
      largest_sq = std::max(largest_sq, point.distance_sq);
    }
    moved_.block_max_sq[k] = largest_sq;
  });
  // The faces the points left, emptied; by face of the fan: its new points after those it
  // kept, then its moments, which the next costings of the edges around vs need (a star this
  // rich is costed on them).
  moved_.fan_taken.assign(fan, 0);
  for (const Reprojection::Source& from : sources) {
    if (from.face == kNoId) continue;
    if (!from.removed) {
      moved_.fan_taken[size_t(from.home)] = 1;
      continue;
    }
    face_points_[from.face].clear();
    face_points_[from.face].shrink_to_fit();
  }
  team_->run(fan, [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      std::vector<FacePoint>& list = face_points_[faces[j]];
      if (moved_.fan_taken[j]) list.clear();
      const FacePoint* first = &moved_.by_face[0] + moved_.fan_start[j];
      const FacePoint* last = &moved_.by_face[0] + moved_.fan_start[j + 1];
      if (first == last) continue;
      list.insert(list.end(), first, last);
      evaluator_.extend(faces[j], size_t(last - first));
    }
  });
  return *std::max_element(moved_.block_max_sq.begin(), moved_.block_max_sq.end());
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
  for (size_t i = 0; i < moved_.count; ++i) {
    const FaceId f = moved_.faces[i];
    const int k = corner_of(mesh.face(f), done.vs);
    const auto& b = moved_.bary[i];
    const auto w = corners(f, k);
    scalar_.add(scalar_.group_of(w[0]), moved_.points[i].id, b[k], w[1], b[(k + 1) % 3], w[2],
                b[(k + 2) % 3]);
  }
  scalar_.apply(done.changed_wedges, done.changed_values);
  for (size_t i = 0; i < moved_.count; ++i) {
    const FaceId f = moved_.faces[i];
    const uint32_t id = moved_.points[i].id;
    scalar_.set_residual(id, scalar_.residual_against(id, mesh.corner_wedges(f), moved_.bary[i]));
  }
}

void EnergyPriority::collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                               const EdgeFaces& edge) {
  // Every point of the old star goes to its closest face of the new one; so do the samples
  // of vt (removed) and of vs if it moved. A star too rich in points moves only those of the
  // removed faces and the samples (see the header).
  team_awake_ = false;
  const auto& faces = mesh.faces_of(done.vs);
  size_t in_star = 0;
  for (FaceId f : {edge.left, edge.right})
    if (f != kNoId) in_star += face_points_[f].size();
  for (FaceId f : faces) in_star += face_points_[f].size();
  const bool keep_faces = !reprojects_every_point(in_star);
  auto index_of = [&](VertexId corner) {
    for (size_t j = 0; j < faces.size(); ++j)
      if (corner_of(mesh.face(faces[j]), corner) >= 0) return int(j);
    return -1;
  };
  // The points that move, in this order: the removed faces', the fan's (unless it keeps
  // them), the unparked samples, the fan's faces that drifted. Listed first, moved after.
  moved_.sources.clear();
  moved_.count = 0;
  for (const auto& [removed, apex] :
       {std::pair{edge.left, edge.left_apex}, std::pair{edge.right, edge.right_apex}})
    if (removed != kNoId)  // (its stored distances may lag: moved, each is computed anew)
      take(removed, index_of(apex), true);
  if (!keep_faces)
    for (size_t j = 0; j < faces.size(); ++j) take(faces[j], int(j), false);
  unpark(done.vt);
  const uint32_t vs_sample = parked_point_[done.vs];
  // vs's own sample stays exact while vs stays put, unless E_scalar gives its wedges new
  // values.
  if (vs_sample != kNoPoint && (positions_[vs_sample] != done.position || scalar_.enabled()))
    unpark(done.vs);
  double max_distance_sq = curves_.collapsed(done.vs, done.vt, mesh);
  if (faces.empty()) {
    move_taken_points();  // (the lists of a component's last faces emptied)
    return;
  }
  if (keep_faces) {
    // A point's closest point on a face of the fan is b0 v + b1 p1 + b2 p2, with v where vs
    // or vt was: it moves by at most b0 |v - old|.
    const Vec3 to_s = sub(done.position, done.vs_before);
    const Vec3 to_t = sub(done.position, mesh.position(done.vt));  // (vt keeps its position)
    const double shift = std::sqrt(std::max(dot(to_s, to_s), dot(to_t, to_t)));
    for (size_t j = 0; j < faces.size(); ++j) {
      const FaceId f = faces[j];
      if (face_points_[f].empty()) continue;
      // A face whose corners have moved by more than a quarter of its size since its points
      // were projected no longer lies over them: they are projected again.
      if (drift_[f] + shift > 0.25 * face_size(mesh, f)) {
        take(f, int(j), false);
        continue;
      }
      // The points are the same (their moments too), the corners not.
      const double stored_sq = evaluator_.corners_moved(f);
      drift_[f] += shift;
      const double bound = std::sqrt(stored_sq) + drift_[f];
      max_distance_sq = std::max(max_distance_sq, bound * bound);
    }
  }
  prepare_fan(mesh, done.vs);
  const size_t moving = moved_.count;
  // Point i's face and projection (independent of the others': on the team when there are
  // enough of them), from where it was (its home: the index among vs's faces of its old
  // face's image, -1 for an unparked sample), into the per-point buffers.
  auto project = [&](size_t i, FacePoint point, int home) {
    const auto [j, best] = closest_fan_face(mesh, faces, point, home);
    moved_.in_fan[i] = j;
    moved_.faces[i] = faces[j];
    moved_.bary[i] = best.bary;
    point.distance_sq = best.distance_sq;
    moved_.points[i] = point;
  };
  // Last point first: each face then lists its points newest first (see initialize()).
  team_awake_ = team_ && moving >= team_->min_items();
  if (team_awake_) {
    max_distance_sq = std::max(max_distance_sq, list_on_team(faces, project));
  } else {
    move_taken_points();
    for (size_t i = 0; i < moving; ++i) project(i, moved_.points[i], moved_.homes[i]);
    for (size_t i = moving; i-- > 0;) {
      face_points_[moved_.faces[i]].push_back(moved_.points[i]);
      evaluator_.forget(moved_.faces[i]);
      max_distance_sq = std::max(max_distance_sq, moved_.points[i].distance_sq);
    }
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
  moved_.prepared.clear();
  moved_.fan.clear();
  for (FaceId f : faces) {
    const Triangle& t = mesh.face(f);
    const Vec3 &p0 = mesh.position(t[0]), &p1 = mesh.position(t[1]), &p2 = mesh.position(t[2]);
    moved_.prepared.emplace_back(p0, p1, p2);
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
    moved_.fan.push_back(fan);
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
                                                            std::span<const FaceId> faces,
                                                            const FacePoint& point,
                                                            int home) const {
  const Vec3& x = point.position;
  int best_j = -1;
  Projection best;
  double best_score = std::numeric_limits<double>::infinity();
  auto consider = [&](int j) {
    const Projection p = moved_.prepared[j].project(x);
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
    const FanFace& fan = moved_.fan[j];
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
    best = moved_.prepared[0].project(x);
  }
  return {best_j, best};
}

}  // namespace parapm
