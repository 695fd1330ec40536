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
// corners; it keeps a bound of how far they moved (drift_), and every distance it reports is
// stored distance + drift, an upper bound (the error recorded in the PM stays one). Once its
// corners have moved by a quarter of its size, its points no longer lie over it: the next such
// collapse projects them again. A costing that projects a face's points measures their
// distances to it afresh: the bound is an error's, not the energy's.
//
// Two terms from Lindstrom and Turk ("Fast and memory efficient polygonal simplification", 98)
// join Hoppe's, for what one point per vertex does not see: the surface between the points.
// Both measure the collapse against the star as it is before it (memoryless; the points keep
// the memory of the input), each scaled to the star's points so that it weighs like E_dist:
// - the star's planes: the squared distances from v to the planes of the star's faces before
//   the collapse, weighted by area, as points spread over those faces at star_planes_weight
//   times the density of the star's own points would measure them (a dense sampling's view at
//   a quadric's price, not per point). It keeps flat and cylindrical patches, which springs
//   and vertex samples alone bend. With them, the boundary planes of the star's open boundary
//   edges at the moving end (Garland-Heckbert's, weighed as the star's own points would see
//   them): the points, of the input measured against the level, do not see a border closing
//   in over its hole.
// - volume preservation: the change of enclosed volume, spread over the star's area, costed
//   as if every point of the star moved by that mean displacement, times volume_weight.
// Both are quadratic in v: the solves minimise them with the rest (measured:
// docs/decisions/notebook-2026-11.md, "The star's planes and its volume").
//
// Queue keys (Costing::kQueue) are most of the evaluations and most are never used: they try
// fewer starts (a young star the two ends, a star costed by moments the midpoint), and each
// start is measured and solved, but the solved position is costed on the model it was solved
// on, not measured again (EnergyEvaluator::place).
//
// The sample of a vertex that has not moved lies on the mesh, on that vertex, whatever
// happens around it: it is "parked" at its vertex (in no face's list) and costs nothing until
// a collapse moves or removes the vertex. Early on, that is almost every point.
//
// The module is in three parts: the state and the performed collapse (this class,
// energy_priority.cpp), the costing of a candidate (EnergyEvaluator, energy_evaluator.h, one
// per module, owning its working memory), and the state's transfer to and from the parallel
// build's jobs (energy_state_transfer.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "simplify/energy_evaluator.h"
#include "simplify/module_state.h"
#include "simplify/modules.h"
#include "simplify/point_moments.h"
#include "simplify/point_projection.h"
#include "simplify/quadric.h"
#include "simplify/scalar_attributes.h"
#include "simplify/sharp_curves.h"
#include "util/zeroed_array.h"

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
  // Price the collapse of a component's last faces (unless SimplifyOptions::keep_components);
  // false: such a collapse cannot be placed, as the component minimum forbids it anyway.
  bool components_may_vanish = false;
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
  // The star's planes and volume preservation (see the top; 0: off). The weights' choice:
  // docs/DECISIONS.md, "The star's planes" and "The volume term at 64".
  double star_planes_weight = 30;
  double volume_weight = 64;
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

  static constexpr uint32_t kNoPoint = 0xffffffffu;  // no point (a vertex without a parked sample)

  EnergyPriority(std::vector<uint8_t> locked, EnergyOptions options,
                 WedgeAttributes attributes = {})
      : locked_(std::move(locked)),
        options_(options),
        attributes_(std::move(attributes)),
        star_terms_on_(options.star_planes_weight > 0 || options.volume_weight > 0) {}
  EnergyPriority(const EnergyPriority&) = delete;  // its evaluator refers to it
  EnergyPriority& operator=(const EnergyPriority&) = delete;
  std::string name() const override { return "energy"; }
  bool costly() const override { return true; }
  void initialize(const CollapseMesh& mesh) override;
  // The sharp curves, then the sample points drawn, listed on their faces and given their
  // attributes in `loops`' chunks.
  void initialize_in_chunks(const CollapseMesh& mesh, ChunkedLoops& loops) override;
  // Costed by the module's evaluator (energy_evaluator.h). With Costing::kQueue each start's
  // solve is costed on the model it was solved on, not measured again.
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    return evaluator_.evaluate(mesh, a, b, out, costing);
  }
  bool evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                     CollapseCandidate& out, Costing costing) override {
    return evaluator_.evaluate(mesh, std::min(vs, vt), std::max(vs, vt), out, costing,
                               EnergySeam{vs, at});
  }
  // On the team, one edge per range, when the collapse before woke it (its projections ran
  // there) and there are two edges or more, or when there are kEdgesWakingTheTeam or more (a
  // first queue's), without E_scalar (whose costing writes the module's attribute scratch):
  // each range costs on a view of the evaluator.
  void evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                     Costing costing) override;
  static constexpr size_t kEdgesWakingTheTeam = 64;
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) override;
  uint64_t costings() const override;
  void release_caches() override { evaluator_.release(); }
  // A collapse moving at least the team's min_items() points projects them, and lists them
  // and sums their moments by face, on the team; the edges around it are then costed there
  // (evaluate_each).
  void use_team(ThreadTeam* team) override { team_ = team; }

  // State export/import for the parallel construction (module_state.h). export_local: the
  // state of a job's faces and vertices (maps: its local -> global ids; the points on its
  // faces, the parked samples of its vertices, their sharp neighbours and curve samples, its
  // wedges), in its local ids. import_local: a job's module from that state, instead of
  // initialize() (no sampling: the points are the master's). export_global: what the job
  // changed, in global ids: the faces around the vertices its collapses moved or removed
  // (changed: per local vertex; dead faces with empty lists), their corners and wedges. Those
  // vertices are free (subset_rule.h), so all of it is the job's own; the rest of its part is
  // as the master exported it, and the master keeps it (so a returned state holds what
  // changed, not every point of the job), without positions (EnergyState::positions).
  // import_global: the master overwrites the state's faces, vertices and wedges, the points
  // and curve samples at the positions it holds for their ids.
  // `loops`: the points' passes in its chunks (a tail round's few jobs, on the cores the round
  // leaves idle); the same state and module whatever the chunking. import_local refuses a
  // state that lists a face's points apart or parks two points at a vertex (kInvalidInput:
  // its chunks each fill whole lists).
  EnergyState export_local(const IdMaps& maps, ChunkedLoops& loops) const;
  EnergyState export_local(const IdMaps& maps) const {
    ChunkedLoops plain;
    return export_local(maps, plain);
  }
  void import_local(const CollapseMesh& mesh, const EnergyState& state, ChunkedLoops& loops);
  void import_local(const CollapseMesh& mesh, const EnergyState& state) {
    ChunkedLoops plain;
    import_local(mesh, state, plain);
  }
  EnergyState export_global(const CollapseMesh& mesh, const IdMaps& maps,
                            const std::vector<uint8_t>& changed, ChunkedLoops& loops) const;
  EnergyState export_global(const CollapseMesh& mesh, const IdMaps& maps,
                            const std::vector<uint8_t>& changed) const {
    ChunkedLoops plain;
    return export_global(mesh, maps, changed, plain);
  }
  void import_global(const EnergyState& state);  // checks the state first (kInvalidInput)
  // For a compact copy of the whole live mesh that runs in-process as the master would run on
  // the whole mesh (parallel/live_pass.h): export_local with the faces' stored distances, not
  // their bounds, and each face's drift (per face of maps.face) in `drifts`; the copy's module
  // imports the state (import_local), then takes the drifts (set_drifts). A job's state folds
  // the drift into its distances instead: its costings see bounds where the master's see the
  // points measured again.
  EnergyState export_with_drifts(const IdMaps& maps, ChunkedLoops& loops,
                                 std::vector<double>& drifts) const;
  // Throws Error(kInvalidInput) unless `drifts` holds a finite, non-negative drift per face.
  void set_drifts(const std::vector<double>& drifts);
  // A job's module (or a live copy's, `drifts`) read straight from a master in this process:
  // the module import_local(mesh, master.export_local(maps)) makes (with `drifts`, also
  // export_with_drifts' and set_drifts'), without the state's copy of every point in between.
  // Only without attributes, in either module (carries_attributes; a job's from its mesh):
  // their point values travel in the state.
  bool carries_attributes() const { return scalar_.enabled(); }
  void import_from(const EnergyPriority& master, const CollapseMesh& mesh, const IdMaps& maps,
                   bool drifts, ChunkedLoops& loops);

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
  // `loops`: a state's passes over its faces, vertices and points in its chunks (a tail round's
  // few states, on the cores the round leaves); the same checks and master whatever the
  // chunking. check_global also refuses a face or vertex listed twice and a face whose points
  // are not listed together, in one run (apply_global's chunks each fill whole lists).
  void begin_global_imports();
  GlobalImport check_global(const EnergyState& state, uint32_t subset, const GlobalOwners& owners,
                            ChunkedLoops& loops) const;
  GlobalImport check_global(const EnergyState& state, uint32_t subset,
                            const GlobalOwners& owners) const {
    ChunkedLoops plain;
    return check_global(state, subset, owners, plain);
  }
  void apply_global(const EnergyState& state, const GlobalImport& import, ChunkedLoops& loops);
  void apply_global(const EnergyState& state, const GlobalImport& import) {
    ChunkedLoops plain;
    apply_global(state, import, plain);
  }
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
  friend class EnergyEvaluator;  // the costing half of the module: reads its state
  using FacePoint = EnergyFacePoint;
  // Whether a performed collapse whose star's faces hold this many points projects every one
  // of them again (else it keeps its faces' points where they are: see the top).
  bool reprojects_every_point(size_t points_on_faces) const {
    const uint32_t cap = options_.max_points_per_reprojection;
    return scalar_.enabled() || cap == 0 || points_on_faces <= cap;
  }
  // kTopologyPrice's price per point for a mesh of this diagonal (the whole mesh's in every
  // subset, so that every job prices alike): (kTopologyPrice x diagonal)^2.
  static double topology_price(double diagonal);

  void prepare_fan(const CollapseMesh& mesh, VertexId vs);
  std::pair<int, Projection> closest_fan_face(const CollapseMesh& mesh,
                                              std::span<const FaceId> faces, const FacePoint& point,
                                              int home) const;
  void update_attributes(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge);
  // The stored squared distance of a point of face f, raised by f's drift (an upper bound).
  double bounded_distance_sq(FaceId f, const FacePoint& p) const {
    if (drift_[f] == 0) return p.distance_sq;
    const double d = std::sqrt(p.distance_sq) + drift_[f];
    return d * d;
  }
  // collapsed()'s plan of the points that move (Reprojection::sources): v's parked sample;
  // face f's points (its moments and drift dropped now), `home` the index of f's image among
  // vs's faces, `removed` for a face the collapse removes. move_taken_points() or list_on_team()
  // moves them.
  void unpark(VertexId v);
  void take(FaceId f, int home, bool removed);
  // The per-point buffers of Reprojection grown to its count (they only grow).
  void grow_moved_buffers();
  // The planned points into the first Reprojection::count of Reprojection::points, their
  // faces emptied.
  void move_taken_points();
  static constexpr size_t kBlocksPerRange = 4;  // list_on_team's blocks of points per range
  // The planned points, read where they are, projected by `project` (point i, and its home)
  // and listed on their new faces of `faces` (vs's), the faces they left emptied and each
  // face's moments extended, on the team: by blocks of points, then by face. Returns the
  // points' largest squared distance.
  double list_on_team(std::span<const FaceId> faces,
                      const std::function<void(size_t i, FacePoint point, int home)>& project);
  FacePoint parked(uint32_t id) const { return {positions_[id], 0.0, id}; }
  double diagonal_of(const CollapseMesh& mesh) const;
  void initialize_curves(const CollapseMesh& mesh, ChunkedLoops& loops);  // curves_ only
  void initialize_points(const CollapseMesh& mesh, ChunkedLoops& loops);  // everything else
  // Empty point lists, moments and drifts for every face, no parked sample: the start of
  // initialize_points and import_local.
  void reset_point_lists(const CollapseMesh& mesh, ChunkedLoops& loops);
  // Where each of `faces`' lists starts in a state listing them in that order (then the end of
  // the last), and in `points` how many points they and `vertices`' parked samples hold.
  std::vector<size_t> first_points(const std::vector<FaceId>& faces,
                                   const std::vector<VertexId>& vertices, size_t& points) const;
  void export_state(const std::vector<FaceId>& faces, const std::vector<VertexId>& vertices,
                    const std::vector<WedgeId>& wedges, const IdMaps& maps, bool to_local,
                    EnergyState& out, ChunkedLoops& loops,
                    std::vector<double>* drifts = nullptr) const;

  std::vector<uint8_t> locked_;
  EnergyOptions options_;
  std::vector<Vec3> positions_;                      // per point (they never move)
  std::vector<std::vector<FacePoint>> face_points_;  // per face: the points projecting onto it
  std::vector<uint32_t> parked_point_;  // per vertex: its sample while it has not moved
  // Per face: how far the closest surface points of its points may have moved since their
  // distances were stored (a rich star's collapse leaves a face its points: see the top).
  std::vector<double> drift_;
  SharpCurves curves_;
  WedgeAttributes attributes_;  // the input's; initialize copies them into scalar_
  // Its star scratch (begin_star, add) is written by the evaluator, which holds the module
  // const: the one part of the module's state a costing writes.
  mutable ScalarAttributes scalar_;
  double topology_price_ = 0;       // per point of the star, for a change of the curves' topology
  std::vector<uint32_t> point_id_;  // a job's: per point, the master's id (empty: identity)
  bool star_terms_on_ = false;      // either of the star's weights is non-zero
  EnergyEvaluator evaluator_{*this};
  ThreadTeam* team_ = nullptr;  // use_team
  bool team_awake_ = false;     // the last collapse ran its projections on the team
  // evaluate_each's: a view of evaluator_ per range, the faces around the edges' ends.
  std::vector<std::unique_ptr<EnergyEvaluator>> views_;
  std::vector<FaceId> view_faces_;

  // collapsed()'s working memory: the points it moves, where they go, the fan around vs.
  struct FanFace {
    Vec3 center{};      // the face's centroid
    double radius = 0;  // of the disc around the centroid that holds the face
    Vec3 normal{};      // unit (0 for a degenerate face)
  };
  struct Reprojection {
    // Where the points come from, in order: a face's whole list, or one sample (face kNoId),
    // starting at index `at` of points.
    struct Source {
      FaceId face;
      int home;
      bool removed;
      size_t at;
      FacePoint sample;
    };
    std::vector<Source> sources;
    // The points moving are the first `count` of each per-point buffer: zeroed pages with room
    // for all of the module's points, given once (grow_moved_buffers), so that a page is
    // written first where the point is (on the team), and never copied or cleared again.
    size_t count = 0;
    ZeroedArray<FacePoint> points;
    // Per point: the index among vs's faces of its old face's image (-1: an unparked sample).
    ZeroedArray<int> homes;
    std::vector<PreparedTriangle> prepared;  // vs's faces
    std::vector<FanFace> fan;
    ZeroedArray<int> in_fan;                  // per point, its new face's index among vs's
    ZeroedArray<FaceId> faces;                // and the face
    ZeroedArray<std::array<double, 3>> bary;  // and its barycentric coordinates there
    // list_on_team's: per block and face of the fan, a count, then an index in by_face; the
    // moved points grouped by their new face, face j's from fan_start[j]; per block, its
    // points' largest distance.
    std::vector<size_t> slots;
    ZeroedArray<FacePoint> by_face;  // (as the per-point buffers)
    std::vector<size_t> fan_start;
    std::vector<double> block_max_sq;
    std::vector<uint8_t> fan_taken;  // per face of the fan: its points were taken
  };
  Reprojection moved_;
  // check_global's marks: (generation << 10) | (subset << 1) | given (a point: named by the
  // state; a face: its run of points begun; a vertex: listed). Each check writes its own
  // subset's faces, vertices and the points on them, all through atomic_ref (its chunks too).
  mutable std::vector<uint32_t> face_tag_, vertex_tag_, point_tag_;
  uint32_t import_generation_ = 0;
};

}  // namespace parapm
