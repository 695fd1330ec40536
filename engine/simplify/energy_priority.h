// The energy priority module: Hoppe's mesh-optimisation energy (Mesh Optimization, SIGGRAPH 93;
// Progressive Meshes, SIGGRAPH 96 section 4) as the cost of an edge collapse.
//
//   E = E_dist + E_spring + E_disc, where E_dist is the sum of squared distances from points
//   sampled on the original surface to the current mesh (each point keeps the face it
//   projects onto), E_spring = kappa * sum over edges of |e|^2, with kappa adapted per
//   collapse from the ratio of points to faces around the edge (a regulariser that fades as
//   points accumulate: Hoppe's schedule, scaled by EnergyOptions::spring_scale), and E_disc the
//   same distance for points sampled on the sharp curves (boundaries, creases, seams), measured
//   against the curves (sharp_curves.h), and E_scalar the attributes' error at the same points
//   (scalar_attributes.h). A collapse that changes the curves' topology pays a finite price.
//
// The cost of collapsing {a, b} is the change of E, less E_spring, restricted to the star of
// the edge and the points on it, with the surviving vertex placed by the best of three starts
// (a, b, the midpoint), each refined by alternating projection of the points onto the new
// star and a least-squares solve for the position (one moving vertex: the normal equations
// are a scalar times the identity, solved in closed form). The springs shape that solve (a
// regulariser) but neither choose among the placements nor price the collapse: priced, their
// change (the star's squared edge lengths) let collapses that moved a curved surface go first
// where they shortened long edges, and held back exact ones that lengthened them. As in Hoppe 96,
// the attributes do not move the vertex: with the position chosen, the wedges' values are solved
// for and their change of E_scalar is added to the cost.
//
// Bounded cost, the fix for the 1999 implementation's quadratic behaviour: late collapses
// cover hundreds of points. A star holding more than max_points_per_evaluation points is
// measured on its faces' point moments (point_moments.h, kept per face until its points
// change): the points' squared distances to each face's plane, before and after, and the
// placement by iteratively reweighted least squares on those planes, both O(faces of the
// star) whatever its points. Smaller stars project each point onto the new star (and may move
// it to the face beside). E_scalar and E_disc cost each point or curve sample they see: beyond
// max_sampled_points, every k-th one stands for k. The collapse actually performed re-projects
// every point of its star onto its closest face, so that the stored distances, and the error
// recorded in the PM, are exact; but a star holding more than max_points_per_reprojection
// points (the last collapses of a large mesh: thousands) only re-projects the points of the
// two faces it removes and the samples of its vertices, and the other faces keep theirs, their
// moments still valid: O(faces) again. Such a face's stored distances then lag behind its
// corners; it keeps a bound of how far they moved (drift_), and every distance read from it
// is stored distance + drift, an upper bound (the error recorded in the PM stays one).
//
// Two terms from Lindstrom and Turk ("Fast and memory efficient polygonal simplification", 98)
// join Hoppe's, for what one point per vertex does not see: the surface between the points.
// Both measure the collapse against the star as it is before it (memoryless; the points keep
// the memory of the input), each scaled to the star's points so that it weighs like E_dist:
// - the star's planes: the squared distances from v to the planes of the star's faces before
//   the collapse, weighted by area, as points spread over those faces at star_planes_weight
//   times the density of the star's own points would measure them (a dense sampling's view at
//   a quadric's price, not per point). It keeps flat and cylindrical patches, which springs
//   and vertex samples alone bend.
// - volume preservation: the change of enclosed volume, spread over the star's area, costed
//   as if every point of the star moved by that mean displacement, times volume_weight.
// Both are quadratic in v: the solves minimise them with the rest (measured:
// docs/decisions/notebook-2026-11.md, "The star's planes and its volume").
//
// Queue keys (Costing::kQueue) are most of the evaluations and most are never used: they try
// fewer starts (a young star the two ends, a star costed by moments the midpoint), and each
// start is measured and solved, but the solved position is costed on the model it was solved
// on, not measured again (see evaluate()).
//
// The sample of a vertex that has not moved lies on the mesh, on that vertex, whatever
// happens around it: it is "parked" at its vertex (in no face's list) and costs nothing until
// a collapse moves or removes the vertex. Early on, that is almost every point.
#pragma once

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "simplify/module_state.h"
#include "simplify/modules.h"
#include "simplify/point_moments.h"
#include "simplify/point_projection.h"
#include "simplify/quadric.h"
#include "simplify/scalar_attributes.h"
#include "simplify/sharp_curves.h"

namespace parapm {

struct EnergyOptions {
  double samples_per_face = 0;  // extra area-weighted points, beyond one per vertex
  uint64_t seed = 1;            // of those extra points
  // Stars with more points are costed by their faces' point moments, not point by point.
  uint32_t max_points_per_evaluation = 16;
  // Beyond this many, E_scalar's points and E_disc's curve samples are costed on every k-th
  // one, weighted by k (their cost is per point, not per face). 0: all of them.
  uint32_t max_sampled_points = 64;
  // A performed collapse whose star holds more points re-projects only the points that must
  // move (see above). 0: always every point. Not with E_scalar (its residuals are per point).
  uint32_t max_points_per_reprojection = 1024;
  // E_spring's kappa is Hoppe's schedule (spring_constant) times this. Hoppe's own values,
  // with one point per vertex (about one per two faces), make a young star's springs outweigh
  // its points' distances many times over: collapses are then ordered and placed by edge
  // length, a smoothing, not by distance (docs/decisions/notebook-2026-11.md, "E_spring's weight").
  double spring_scale = 0.03;
  int solves_per_start = 1;     // least-squares solves after the first projection, per start
  bool round_to_float = false;  // place vertices on float32 coordinates (exact PM storage)
  bool discontinuities = true;  // E_disc: sample and keep the sharp curves (sharp_curves.h)
  SharpEdgeOptions sharp;
  // E_scalar's c_scalar relative to the bounding-box diagonal: an attribute difference of 1
  // (a colour channel's whole range) costs as much as a distance of weight x diagonal. 0: off
  // (the wedges keep their input values at every level).
  double attribute_weight = 0;
  // The scale costs are measured against: the bounding-box diagonal of the whole mesh. 0: that
  // of the mesh the module is given. A subset job passes the whole mesh's, so that the costs of
  // different subsets (and the weights derived from the diagonal) are comparable.
  double reference_diagonal = 0;
  // The star's planes and volume preservation (see the top; 0: off). Chosen on 18 meshes
  // among 1 ... 100 and 0 ... 16: larger plane weights lowered RMS at 50% further but raised
  // Hausdorff at 10%, at more time.
  double star_planes_weight = 10;
  double volume_weight = 4;
};

// The input's wedge values, for E_scalar (CollapseMesh holds only the corners' wedge ids).
struct WedgeAttributes {
  AttributeLayout layout;
  std::vector<float> values;  // layout.floats_per_wedge() per wedge
};

// Hoppe 96 section 4.2: the spring constant from the ratio r of points to faces in the
// neighbourhood: 1e-2 when r < 4, 1e-4 when r < 8, 1e-8 beyond.
double spring_constant(double points_per_face);

class EnergyPriority : public PriorityModule {
 public:
  // A collapse that changes the curves' topology pays, for each point of its star, the
  // energy of a point moved by this fraction of the reference diagonal: a finite price (Hoppe
  // 96's E_disc is one), so that an ordinary collapse moving the star's points farther than
  // that on average waits behind it.
  static constexpr double kTopologyPrice = 0.003;

  EnergyPriority(std::vector<uint8_t> locked, EnergyOptions options,
                 WedgeAttributes attributes = {})
      : locked_(std::move(locked)),
        options_(options),
        attributes_(std::move(attributes)),
        star_terms_on_(options.star_planes_weight > 0 || options.volume_weight > 0) {}
  std::string name() const override { return "energy"; }
  bool costly() const override { return true; }
  void initialize(const CollapseMesh& mesh) override;
  // The sharp curves, and the rest (the sample points, the per-face lists, E_scalar).
  std::vector<std::function<void()>> initialization_parts(const CollapseMesh& mesh) override;
  // With Costing::kQueue each start's solve is costed on the model it was solved on, not
  // measured again (see evaluate()).
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) const override;
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) override;
  uint64_t costings() const override { return costings_; }

  // State export/import for the parallel construction (module_state.h). export_local: the
  // state of a job's faces and vertices (maps: its local -> global ids; the points on its
  // faces, the parked samples of its vertices, their sharp neighbours and curve samples, its
  // wedges), in its local ids. import_local: a job's module from that state, instead of
  // initialize() (no sampling: the points are the master's). export_global: what the job
  // changed, in global ids: the faces around the vertices its collapses moved or removed
  // (changed: per local vertex; dead faces with empty lists), their corners and wedges. Those
  // vertices are free (subset_rule.h), so all of it is the job's own; the rest of its part is
  // as the master exported it, and the master keeps it (so a returned state holds what
  // changed, not every point of the job). import_global: the master overwrites the state's
  // faces, vertices and wedges.
  EnergyState export_local(const IdMaps& maps) const;
  void import_local(const CollapseMesh& mesh, const EnergyState& state);
  EnergyState export_global(const CollapseMesh& mesh, const IdMaps& maps,
                            const std::vector<uint8_t>& changed) const;
  void import_global(const EnergyState& state);  // checks the state first (kInvalidInput)

  // Several jobs' states at once (job_state.h, import_result_states), side by side:
  // begin_global_imports() once; check_global() of every state, each on its own thread if
  // wished (each state k of a different subset); then, if none threw, apply_global() of every
  // state, side by side too; then apply_global_wedges() of each, one after the other.
  // `owners`: per vertex the subset owning it, per face the subset owning its three corners
  // (kNoId: none); a state may list only its own subset's (null: not checked, one state
  // alone). check_global throws Error(kInvalidInput) and changes no state (only its marks).
  struct GlobalOwners {
    const std::vector<uint32_t>* vertex_subset = nullptr;
    const std::vector<uint32_t>* face_subset = nullptr;
  };
  struct GlobalImport {
    std::vector<uint32_t> samples;  // indices into state.samples that this state writes
  };
  void begin_global_imports();
  GlobalImport check_global(const EnergyState& state, uint32_t subset,
                            const GlobalOwners& owners) const;
  void apply_global(const EnergyState& state, const GlobalImport& import);
  void apply_global_wedges(const EnergyState& state);

  // Observers, for tests and reports.
  size_t point_count() const { return positions_.size(); }
  struct PointState {
    Vec3 position{};
    double distance_sq = 0;   // to its face, as of the last collapse that touched it
    FaceId face = kNoId;      // the face it projects onto; kNoId while parked
    VertexId parked = kNoId;  // the vertex it is the sample of, while that vertex has not moved
  };
  // Every point's state, by id (a scan of every face: for tests and reports).
  std::vector<PointState> point_states() const;
  // How many points the faces' lists and the parked samples hold together: each point at most
  // once, so at most point_count() (a scan, for tests).
  size_t held_point_count() const;
  const SharpCurves& curves() const { return curves_; }
  // How many points or curve samples a candidate's costing sees one by one (the thinning only
  // changes costs, not the state: tests cost one state both ways).
  void set_max_sampled_points(uint32_t n) { options_.max_sampled_points = n; }

 private:
  // kTopologyPrice's price per point for a mesh of this diagonal (the whole mesh's in every
  // subset, so that every job prices alike): (kTopologyPrice x diagonal)^2.
  static double topology_price(double diagonal);
  static constexpr uint32_t kNoPoint = 0xffffffffu;
  // A point as its face holds it: each face keeps its points contiguously, so that the late
  // collapses, whose stars hold hundreds of points, read them in sequence, not one cache miss
  // per point.
  struct FacePoint {
    Vec3 position{};
    double distance_sq = 0;  // to its face, as of the last collapse that touched it
    uint32_t id = kNoPoint;
  };
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

  Fit project_points(const std::vector<FacePoint>& points, const std::vector<int>& homes,
                     const Vec3& v, std::vector<Projected>* where = nullptr) const;
  double scalar_change() const;
  const PointMoments& moments_of(FaceId f) const;
  // Face f's points against its own plane and rim as the mesh has it now: the "before" of
  // every star holding f, kept with its moments.
  struct OwnError {
    double plane_sq = 0, rim_sq = 0;
  };
  const OwnError& own_error_of(const CollapseMesh& mesh, FaceId f) const;
  double plane_distance_sq(FaceId f, const Vec3& q0, const Vec3& q1, const Vec3& q2) const;
  double rim_sq(FaceId f, const Vec3& q0, const Vec3& q1, const Vec3& q2, int star_face = -1) const;
  double moment_rim_change(const CollapseMesh& mesh, const Vec3& v) const;
  double exact_distance_sq() const;
  double moment_distance_before(const CollapseMesh& mesh) const;
  double moment_distance_after(const Vec3& v) const;
  Vec3 moment_solve(const Vec3& from, double iso_a, const Vec3& iso_b,
                    PlaneModel* model = nullptr) const;
  Vec3 projection_solve(const Fit& fit, double iso_a, const Vec3& iso_b, const Vec3& from) const;
  void prepare_fan(const CollapseMesh& mesh, VertexId vs);
  std::pair<int, Projection> closest_fan_face(const CollapseMesh& mesh,
                                              const std::vector<FaceId>& faces,
                                              const FacePoint& point, int home) const;
  void update_attributes(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge);
  void gather_face(FaceId f, int home) const;
  // The points' stored squared distance to face f, raised by its drift (an upper bound).
  double bounded_distance_sq(FaceId f, const FacePoint& p) const {
    if (drift_[f] == 0) return p.distance_sq;
    const double d = std::sqrt(p.distance_sq) + drift_[f];
    return d * d;
  }
  void unpark(VertexId v);
  FacePoint parked(uint32_t id) const { return {positions_[id], 0.0, id}; }
  double diagonal_of(const CollapseMesh& mesh) const;
  void initialize_curves(const CollapseMesh& mesh);  // curves_ only
  void initialize_points(const CollapseMesh& mesh);  // everything else
  // Empty point lists, moments and drifts for every face, no parked sample: the start of
  // initialize_points and import_local.
  void reset_point_lists(const CollapseMesh& mesh);
  void export_state(const std::vector<FaceId>& faces, const std::vector<VertexId>& vertices,
                    const std::vector<WedgeId>& wedges, const IdMaps& maps, bool to_local,
                    EnergyState& out) const;
  bool folds(const Vec3& v) const;

  // evaluate()'s steps, in order. Each fills the scratch members it names; none is
  // thread-safe (the scratch is the module's).
  // 1. Which end survives, and whether its place is fixed (a locked end, an end on a curve the
  //    other is not on, a corner, or a change of the curves' topology); not possible when both
  //    ends are locked.
  struct Survivor {
    bool possible = false;
    bool keep_b = false, fixed = false, topology = false, boundary_a = false, boundary_b = false;
  };
  Survivor choose_survivor(const CollapseMesh& mesh, VertexId a, VertexId b) const;
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
  StarSums gather_star(const CollapseMesh& mesh, VertexId a, VertexId b) const;
  // 3. The fan's order (StarFace::next, previous), the homes of the removed faces' points
  //    (scratch_.edge_face_homes) and the samples of a and b still parked (scratch_.parked_ends).
  //    Returns the parked samples around the star, each counted half (they sit on its rim).
  double link_fan(const StarSums& sums, VertexId a, VertexId b) const;
  // 4. The star's points (scratch_: points, homes, point_weight), all, or thinned
  //    for E_scalar on a large star; whether the star is costed by its faces' moments.
  struct StarPoints {
    bool by_moments = false;
    double points_around = 0;  // the points the star holds, its rim's parked half included
  };
  StarPoints gather_star_points(double parked_around) const;
  // 5. scratch_.terms: the star's planes and its volume, weighted for points_around points.
  void set_star_terms(StarSums& sums, double points_around) const;

  std::vector<uint8_t> locked_;
  EnergyOptions options_;
  std::vector<Vec3> positions_;                      // per point (they never move)
  std::vector<std::vector<FacePoint>> face_points_;  // per face: the points projecting onto it
  std::vector<uint32_t> parked_point_;  // per vertex: its sample while it has not moved
  SharpCurves curves_;
  WedgeAttributes attributes_;  // the input's; initialize copies them into scalar_
  mutable uint64_t costings_ = 0;
  mutable ScalarAttributes scalar_;  // its star scratch is used by the const evaluate
  double topology_price_ = 0;        // per point of the star, for a change of the curves' topology
  std::vector<uint32_t> point_id_;   // a job's: per point, the master's id (empty: identity)

  // The working memory of evaluate() and collapsed() for the star at hand: rebuilt by each
  // call, so a module is used by one thread at a time (the parallel build gives each job its
  // own module); evaluate() is const and writes only here, in the caches below and in
  // costings_.
  struct StarScratch {
    std::vector<StarFace> star;
    // The faces whose points are the star's (the star's sources and the two removed faces),
    // with the star face their points are measured against (-2, -3: the removed faces, homed
    // once the fan is known).
    std::vector<std::pair<FaceId, int>> lists;
    std::vector<VertexId> fan_first_ids, fan_second_ids;  // star's id1, id2
    std::vector<FacePoint> points;
    // Per star point: the star face its face becomes (-1, -2: the samples of a and b). In
    // collapsed(): the index among vs's faces of its old face's image (-1: an unparked sample).
    std::vector<int> homes;
    double point_weight = 1;  // how many points each of `points` stands for
    // The star's planes and volume terms, as one quadric in v - origin (with star_terms_on_).
    Quadric terms;
    Vec3 origin{};
    int a_side_faces = 0;
    std::array<FaceId, 2> edge_faces{kNoId, kNoId};  // the two faces the collapse removes
    std::array<int, 2> edge_face_homes{};            // the star faces their points go to
    std::vector<FacePoint> parked_ends;              // the samples of a and b, while parked
    std::vector<int> parked_end_homes;
    std::array<std::pair<WedgeId, WedgeId>, 2> joined{};  // wedges of a, b in fl, fr
    int joined_count = 0;
    std::vector<Projected> projected;  // per star point, at the chosen placement
    std::array<std::vector<Projected>, 16> placement_projections;
    std::vector<PreparedTriangle> prepared;  // star with v at the projected position
  };
  mutable StarScratch scratch_;
  bool star_terms_on_ = false;  // either of the star's weights is non-zero
  // Per face, the moments of the points projecting onto it (computed when first needed,
  // forgotten when its point list changes).
  mutable std::vector<PointMoments> moments_;
  // 0: nothing known, 1: moments_, 2: moments_ and own_ (a face's corners move only in a
  // performed collapse, which resets this to 0, or to 1 when the face keeps its points).
  mutable std::vector<uint8_t> moments_ready_;
  mutable std::vector<OwnError> own_;
  // Per face: the largest stored squared distance of its points (kept with its moments), and
  // how far the closest surface points of its points may have moved since they were stored.
  mutable std::vector<double> max_distance_sq_;
  std::vector<double> drift_;
  // collapsed(): per face around vs, its centroid, the radius of the disc around it that holds
  // the face, and its unit normal (0 for a degenerate face).
  struct FanFace {
    Vec3 center{};
    double radius = 0;
    Vec3 normal{};
  };
  std::vector<FanFace> fan_;
  // check_global's marks: (generation << 10) | (subset << 1) | given. Each check writes its own
  // subset's faces, vertices and the points on them; the points' marks through atomic_ref.
  mutable std::vector<uint32_t> face_tag_, vertex_tag_, point_tag_;
  uint32_t import_generation_ = 0;
  std::vector<FaceId> moved_faces_;  // collapsed: per star point, its new face
  std::vector<std::array<double, 3>> moved_bary_;
};

}  // namespace parapm
