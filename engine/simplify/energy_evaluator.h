// The energy's costing of one collapse (what is costed, and why: energy_priority.h). An
// evaluator gathers the star of the edge and its points, places the surviving vertex from its
// starts and prices the change of E.
//
// Ownership: one evaluator per EnergyPriority (and views of it, one per thread of its team),
// which it reads (its points, curves, options) but does not change. It owns its working memory (the
// star at hand) and the per-face caches derived from the module's points (their moments and their
// errors against their own faces), which the module invalidates when a collapse changes a face
// (forget, corners_moved). Not thread-safe: a module and its evaluator serve one thread at a time
// (the parallel build gives each job its own module), but for views, which cost side by side on the
// owner's caches while the owner waits (EnergyPriority::evaluate_each).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "simplify/modules.h"
#include "simplify/point_moments.h"
#include "simplify/point_projection.h"
#include "simplify/quadric.h"
#include "simplify/sharp_curves.h"
#include "util/zeroed_array.h"

namespace parapm {

class EnergyPriority;

// A sample point as a face holds it: each face keeps its points contiguously, so that the late
// collapses, whose stars hold hundreds of points, read them in sequence, not one cache miss per
// point.
struct EnergyFacePoint {
  Vec3 position{};
  double distance_sq = 0;  // to its face, as of the last collapse that touched it
  uint32_t id = 0;
};

// A seam collapse's costing (EnergyEvaluator::evaluate): the end that survives, and its place
// (null: where the evaluator places it best).
struct EnergySeam {
  VertexId keep = kNoId;
  const Vec3* at = nullptr;
};

class EnergyEvaluator {
 public:
  explicit EnergyEvaluator(const EnergyPriority& module) : module_(module) {}
  // A view of `owner` (EnergyPriority::evaluate_each): its own working memory, the owner's
  // per-face caches, read only (what they lack it computes without keeping). Views of one
  // owner may cost side by side while the owner and its module change nothing.
  EnergyEvaluator(const EnergyPriority& module, const EnergyEvaluator& owner)
      : module_(module), shared_(&owner) {}
  EnergyEvaluator(const EnergyEvaluator&) = delete;
  EnergyEvaluator& operator=(const EnergyEvaluator&) = delete;

  // PriorityModule::evaluate for the energy: costs the collapse of {a, b}, choosing the
  // survivor and its place; false when it cannot be placed (both ends locked, no star).
  // With seam.keep (a or b; PriorityModule::evaluate_seam): that end survives, locked or not,
  // at *seam.at when given.
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing, EnergySeam seam = {});
  uint64_t costings() const { return costings_; }

  // The per-face caches. reset: none known, for faces up to `face_capacity`. forget: face f's
  // points or corners changed. corners_moved: f keeps its points (their moments stay valid)
  // but its corners moved; returns the largest stored squared distance of its points.
  // release: frees them (105 bytes per face; a parallel build's master while the jobs run),
  // until the next evaluate, which starts them anew: they are functions of the points and
  // corners, so no costing changes.
  void reset(size_t face_capacity);
  void forget(FaceId f) {
    if (!moments_ready_.empty()) moments_ready_[f] = 0;
  }
  // Face f's list gained `added` points at its end (its other points and order unchanged):
  // its moments made ready now rather than at its next costing, for a collapse's faces on the
  // team's threads, one face per thread at a time. Known moments are extended by the added
  // points only: Welford's sums over the list in order, so the same values as computed anew.
  void extend(FaceId f, size_t added);
  // Before views cost side by side: the caches made whole (after a release), then those of
  // `faces` filled (moments and own errors), which the views then read rather than compute
  // each on its own.
  void fill_for_views(const CollapseMesh& mesh, std::span<const FaceId> faces);
  double corners_moved(FaceId f);
  void release();

 private:
  using FacePoint = EnergyFacePoint;
  // A face of the star after the collapse: (v, p1, p2) counter-clockwise, v the moving vertex
  // (which was at `before`). `next` and `previous` are the faces across the edges (v, p2) and
  // (v, p1) in the fan around v (-1 on a boundary).
  struct StarFace {
    Vec3 p1, p2, before;
    VertexId id1, id2;
    FaceId source = kNoId;  // the face it is the image of
    int next = -1, previous = -1;
    std::array<WedgeId, 3> wedges{};  // of the corners v, p1, p2 (with E_scalar)
    int group = 0;                    // E_scalar's group of the corner at v
  };
  // Where one point projected: a star face and barycentric coordinates on (v, p1, p2).
  struct Projected {
    int face = 0;
    std::array<double, 3> bary{};
  };
  // The projections of the evaluated points onto the star with v at one position, summed
  // for the energy and for the next least-squares solve.
  struct Fit {
    double distance_sq = 0;      // sum over the evaluated points
    double max_distance_sq = 0;  // largest single one
    double a = 0;                // sum of b0^2 (b0: barycentric coordinate of v)
    Vec3 b{};                    // sum of b0 (x - b1 p1 - b2 p2)
    double c = 0;                // sum of |x - b1 p1 - b2 p2|^2
    // The points' squared distances to where their barycentric coordinates put them with the
    // moving vertex at w: sum |x - b0 w - b1 p1 - b2 p2|^2 (the least-squares solve's model).
    double model_at(const Vec3& w) const { return c - 2 * dot(b, w) + a * dot(w, w); }
  };
  // The moment solve's model (moment_solve): the planes' squared distances, each weighted by
  // its normal's length at the start, w^T h w - 2 r.w + k, plus the parked ends' Fit model.
  struct PlaneModel {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    double k = 0;
    Fit ends;
    double at(const Vec3& w) const {
      const Eigen::Vector3d x(w[0], w[1], w[2]);
      return x.dot(h * x) - 2 * r.dot(x) + k + ends.model_at(w);
    }
  };
  // Face f's points against its own plane and rim as the mesh has it now: the "before" of
  // every star holding f, kept with its moments.
  struct OwnError {
    double plane_sq = 0, rim_sq = 0;
  };

  // evaluate()'s steps, in order. Each fills the scratch members it names.
  // 1. Which end survives, and whether its place is fixed (a locked end, an end on a curve the
  //    other is not on, a corner, or a change of the curves' topology); `keep` survives, placed
  //    by those rules but for locks; not possible when both ends are locked (without `keep`).
  struct Survivor {
    bool possible = false;
    bool keep_b = false, fixed = false, topology = false, boundary_a = false, boundary_b = false;
  };
  Survivor choose_survivor(const CollapseMesh& mesh, VertexId a, VertexId b, VertexId keep) const;
  // 2. The star (scratch_: star, lists, edge_faces, joined, a_side_faces, origin), and
  //    the sums over its faces before the collapse: the area-weighted planes, the faces'
  //    normals and normal.corner, twice the area, about scratch_.origin.
  struct StarSums {
    Quadric planes;
    Vec3 normals{};
    double offsets = 0, area2 = 0;
    std::array<VertexId, 2> edge_apexes{kNoId, kNoId};
    int edge_faces = 0;
  };
  StarSums gather_star(const CollapseMesh& mesh, VertexId a, VertexId b);
  // The boundary planes of face t's two edges at its corner k (the star's moving end), each
  // an open boundary edge: the plane through the edge perpendicular to the face (normal n,
  // any length), weighted |e|^2 / star_planes_weight, so that once the star's planes are
  // scaled it weighs as the star's own points (not star_planes_weight times as dense) spread
  // over a right triangle on the edge (legs |e|) would see v leave it. It keeps an open border
  // from closing in over its hole, which the points (of the input, measured against the level)
  // do not see.
  void add_boundary_planes(const CollapseMesh& mesh, const Triangle& t, int k, const Vec3& n,
                           Quadric& planes) const;
  // 3. The fan's order (StarFace::next, previous), the homes of the removed faces' points
  //    (scratch_.edge_face_homes) and the samples of a and b still parked (scratch_.parked_ends).
  //    Returns the parked samples around the star, each counted half (they sit on its rim).
  double link_fan(const StarSums& sums, VertexId a, VertexId b);
  // 4. The star's points (scratch_: points, homes, point_weight), all, or thinned
  //    for E_scalar on a large star; whether the star is costed by its faces' moments.
  struct StarPoints {
    bool by_moments = false;
    double points_around = 0;  // the points the star holds, its rim's parked half included
    // The collapse, performed, projects every point of the star again
    // (EnergyPriority::reprojects_every_point): a point may then go to any face of the star.
    bool reprojected = true;
  };
  StarPoints gather_star_points(const CollapseMesh& mesh, double parked_around);
  // 5. The energy before the collapse (its points' and its curves'), the springs, and
  //    scratch_.terms: the star's planes and its volume, weighted for points_around points.
  struct Before {
    double distance_sq = 0, curves_sq = 0;
  };
  Before energy_before(const CollapseMesh& mesh, VertexId a, VertexId b, bool by_moments);
  struct Springs {
    double weight = 0;  // kappa times the star's faces: the isotropic part of the solve
    Vec3 pull{};        // kappa/2 times the sum of the far corners
  };
  Springs springs_of(double points_around) const;
  void set_star_terms(StarSums& sums, double points_around);
  // 6. The placements (scratch_.placements): the fixed survivor's place, or from each start a
  //    measure and solves (fewer starts for a queue key).
  struct Placing {
    bool by_moments = false;
    bool keep_projections = false;  // each placement keeps its points' projections (E_scalar)
    bool boundary_edge = false;     // both ends on the boundary
    Springs springs;
    Vec3 pa{}, pb{};
  };
  void place(const CollapseMesh& mesh, const CollapseCandidate& out, const Survivor& survivor,
             const Placing& placing, Costing costing, const Vec3* at);
  void measure(const Placing& placing, const Vec3& v, Fit& fit);
  Vec3 solve(const Placing& placing, const Fit& fit, const Vec3& from);
  // 7. The lowest energy among the placements that fold no face (the face-geometry constraint
  //    would veto the others); if all fold, the lowest (and the constraint vetoes it).
  struct Placement {
    Vec3 v;
    double energy;
    double max_distance_sq;
    size_t index;  // into scratch_.placement_projections; kNotProjected for a modelled one
  };
  static constexpr size_t kNotProjected = ~size_t{0};
  const Placement& choose_placement();
  // 8. With E_scalar: its change at the chosen placement (the points' projections there in
  //    scratch_.projected), weighted as the star's planes weigh the geometry.
  double attribute_change(const Placing& placing, const Placement& chosen);

  // The collapse of a component's last faces (ComponentMinimum, when components may vanish):
  // no face is left around either end (the star is empty). Its points have no surface left but
  // the surviving vertex: each costs its squared distance to it (the curves' samples theirs to
  // the segments left), and the vertex goes where their sum is least, unless its place is fixed.
  bool evaluate_removal(const CollapseMesh& mesh, VertexId a, VertexId b, const Survivor& survivor,
                        const Vec3* at, CollapseCandidate& out);

  // The measures and solves the steps share.
  // Face f's points into scratch_.points, with their distances to f as it is now (a face left
  // with its points by a rich star's collapse holds stale ones: EnergyPriority::drift_).
  void gather_face(const CollapseMesh& mesh, FaceId f, int home);
  // From the caches (the owner's, for a view), or computed (and kept, but by a view).
  PointMoments moments_of(FaceId f);
  OwnError own_error_of(const CollapseMesh& mesh, FaceId f);
  double plane_distance_sq(FaceId f, const Vec3& q0, const Vec3& q1, const Vec3& q2);
  // Where rim_sq tries the mean besides (q0, q1, q2): nowhere; the faces beside star face
  // `star_face` after the collapse; every face of the star after it; every face of the star
  // before it (the removed two included, read from `mesh`).
  enum class RimAround { kOwn, kBeside, kStarAfter, kStarBefore };
  double rim_sq(FaceId f, const Vec3& q0, const Vec3& q1, const Vec3& q2, RimAround around,
                int star_face = -1, const CollapseMesh* mesh = nullptr);
  double moment_rim_change(const CollapseMesh& mesh, const Vec3& v, bool reprojected);
  double exact_distance_sq() const;
  double moment_distance_before(const CollapseMesh& mesh);
  double moment_distance_after(const Vec3& v);
  Vec3 moment_solve(const Vec3& from, double iso_a, const Vec3& iso_b, PlaneModel* model = nullptr);
  Vec3 projection_solve(const Fit& fit, double iso_a, const Vec3& iso_b, const Vec3& from) const;
  Fit project_points(const std::vector<FacePoint>& points, const std::vector<int>& homes,
                     const Vec3& v, std::vector<Projected>* where = nullptr);
  bool folds(const Vec3& v) const;
  double scalar_change();

  const EnergyPriority& module_;
  const EnergyEvaluator* shared_ = nullptr;  // a view's owner, whose caches it reads
  uint64_t costings_ = 0;

  // The star at hand: rebuilt by each evaluate().
  struct StarScratch {
    std::vector<StarFace> star;
    // The faces whose points are the star's (the star's sources and the two removed faces),
    // with the star face their points are measured against (-2, -3: the removed faces, homed
    // once the fan is known).
    std::vector<std::pair<FaceId, int>> lists;
    std::vector<VertexId> fan_first_ids, fan_second_ids;  // star's id1, id2
    std::vector<FacePoint> points;
    // Per star point: the star face its face becomes (-1, -2: the samples of a and b).
    std::vector<int> homes;
    double point_weight = 1;  // how many points each of `points` stands for
    // The star's planes and volume terms, as one quadric in v - origin (with star_terms_on).
    Quadric terms;
    Vec3 origin{};
    int a_side_faces = 0;
    std::array<FaceId, 2> edge_faces{kNoId, kNoId};  // the two faces the collapse removes
    std::array<int, 2> edge_face_homes{};            // the star faces their points go to
    std::vector<FacePoint> parked_ends;              // the samples of a and b, while parked
    std::vector<int> parked_end_homes;
    std::array<std::pair<WedgeId, WedgeId>, 2> joined{};  // wedges of a, b in fl, fr
    int joined_count = 0;
    std::array<Placement, 16> placements;
    size_t placed = 0;
    SharpCurves::Gathered curve_samples;  // the curves' samples and segments of the star
    SharpCurves::Fit curve_fit;           // of the placement measured last
    PlaneModel plane_model;               // of the last moment solve
    std::vector<Projected> projected;     // per star point, at the chosen placement
    std::array<std::vector<Projected>, 16> placement_projections;
    std::vector<PreparedTriangle> prepared;  // star with v at the projected position
    std::vector<Vec3> removal_points;        // evaluate_removal's points
  };
  StarScratch scratch_;

  // Per face, the moments of the points projecting onto it (computed when first needed,
  // forgotten when its point list changes).
  ZeroedArray<PointMoments> moments_;
  // 0: nothing known, 1: moments_, 2: moments_ and own_ (a face's corners move only in a
  // performed collapse, which resets this to 0, or to 1 when the face keeps its points).
  ZeroedArray<uint8_t> moments_ready_;
  ZeroedArray<OwnError> own_;
  // Per face: the largest stored squared distance of its points (kept with its moments).
  ZeroedArray<double> max_distance_sq_;
  size_t released_capacity_ = 0;  // the face capacity to reset to (release); 0: not released
};

}  // namespace parapm
