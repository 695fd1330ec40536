// The quadric priority module: Garland & Heckbert 97 plane quadrics, area weighted, with
// boundary-preserving planes along open edges, optimal placement with a fallback. The optimum
// is taken among the placements that keep the volume the edge's star encloses and the area
// its border edges sweep (Lindstrom-Turk 98's first two constraints, placement_constraints.h):
// without them a coarse level shrinks where the surface or its outline curves. A queue key is
// the accumulated quadric's least value (its unconstrained optimum's cost), a lower bound of
// the constrained cost, which reads the star's faces and is paid only for the edge at the top
// (Costing). A sample's estimate (kEstimate) is the constrained cost where the quadric has no
// unique optimum (a flat or creased star), where the least value says least about the cost.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "simplify/module_state.h"
#include "simplify/modules.h"
#include "simplify/placement_constraints.h"
#include "simplify/quadric.h"
#include "simplify/simplifier.h"

namespace parapm {

struct QuadricOptions {
  // Weight of the plane through a boundary edge, perpendicular to its face, relative to the
  // face planes (it is multiplied by the squared edge length to have area units).
  double boundary_weight = 4.0;
  bool round_to_float = false;  // place vertices on float32 coordinates (exact PM storage)
  // The optimum among the placements that keep the star's volume, and its border's area.
  bool keep_volume = true;
  bool keep_border = true;
  // The planes of the star's faces before the collapse, weighted by area and by this, join the
  // accumulated quadric in the performed collapse's placement, not in its cost (0: off). The
  // accumulated quadrics remember the input's planes but not where the level stands now, and
  // at a coarse level place a rim's merged vertex where it bevels the rim; the star's planes
  // (Lindstrom-Turk's memoryless objective, in the quadric's units) hold it there. The cost
  // stays the accumulated quadric's, so that a queue key, its free optimum's cost, stays a
  // close lower bound (docs/DECISIONS.md, "The quadric places with its star's planes").
  double star_planes_weight = 0.3;
  // While the mesh has more live faces than this, a collapse goes where the accumulated quadric
  // alone places it (its free optimum, or the best of the ends and the midpoint), costed there:
  // no star sums (most of a fine level's costing), and a queue key that is the collapse's cost.
  // At the coarse levels below it, where a placement's drift from the star's volume and border
  // shows, the constrained placement above (docs/DECISIONS.md, "The quadric places freely at
  // fine levels"). UINT64_MAX: never free; 0: always.
  uint64_t free_placement_above_faces = UINT64_MAX;
};

class QuadricPriority : public PriorityModule {
 public:
  QuadricPriority(std::vector<uint8_t> locked, QuadricOptions options)
      : locked_(std::move(locked)), options_(options) {}
  std::string name() const override { return "quadric"; }
  void initialize(const CollapseMesh& mesh) override;
  // The faces' twins found in `loops`' chunks; with more than one chunk, each vertex's
  // quadric summed in its chunk (the same bits).
  void initialize_in_chunks(const CollapseMesh& mesh, ChunkedLoops& loops) override;
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override;
  bool evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                     CollapseCandidate& out, Costing costing) override;
  // Each pair's quadrics summed once for all the places.
  void evaluate_seam_at(const CollapseMesh& mesh, std::span<const SeamPair> pairs,
                        std::span<const Vec3> places, Costing costing,
                        std::span<SeamCosting> out) override;
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) override;
  // A queue key is the ends' summed quadric's: at its free optimum, or its least value at the
  // edge's midpoint, or at a locked end; placed freely, where place() puts the survivor.
  bool queue_key_of_ends_only() const override { return true; }
  // Both costings refuse an edge whose ends are both locked; otherwise a queue costing is
  // placed when finite, and the collapse's puts the survivor near the edge or at an end, where
  // the same accumulated quadric is finite too.
  bool placed_when_queued_is_placed() const override { return true; }
  // Prefetches the quadrics (two cache lines each) and lock flags of `from` and `to`.
  void will_cost(VertexId from, std::span<const VertexId> to) const override;
  uint64_t costings() const override { return costings_; }
  std::unique_ptr<PriorityModule> costing_view() const override;

  // State transfer for the parallel construction (module_state.h). export_local: the
  // quadrics of a job's vertices (maps: its local -> global ids), in its local ids.
  // import_local: a job's module from that state, instead of initialize(). A job returns no
  // quadrics: its collapses change them only by collapsed() (Q_vs += Q_vt), so the master
  // follows a job from its records (follow_records), exactly and at the cost of a copy.
  // `free`, when given: per local vertex, whether its quadric goes (a job costs and collapses
  // only edges between free vertices: subset_rule.h).
  QuadricState export_local(const IdMaps& maps, const std::vector<uint8_t>* free = nullptr) const;
  void import_local(const CollapseMesh& mesh, const QuadricState& state);
  // Before follow_records of several jobs side by side (job_state.h): throws
  // Error(kInvalidInput) unless both ends of every record are distinct, in range and, with
  // vertex_subset, the subset's (a dishonest reply naming another subset's vertex would have
  // two threads write it).
  void check_records(const std::vector<CollapseRecord>& records, uint32_t subset,
                     const std::vector<uint32_t>* vertex_subset) const;
  // collapsed()'s change of every record, in order (check_records first).
  void follow_records(const std::vector<CollapseRecord>& records);
  const Quadric& quadric(VertexId v) const { return quadrics_[v]; }
  const QuadricOptions& options() const { return options_; }

 private:
  // Face f's planes, given to add(vertex, quadric) in the order a pass over the faces sums
  // them (twin: CollapseMesh::twin_faces).
  template <typename Add>
  void face_planes(const CollapseMesh& mesh, const std::vector<FaceId>& twin, FaceId f,
                   Add add) const;
  // Every vertex's quadric summed from its own fan, in `loops`' chunks; false (quadrics
  // incomplete) when a fan is not in increasing face order, as a mesh lists it when built.
  bool sum_by_vertex(const CollapseMesh& mesh, const std::vector<FaceId>& twin,
                     ChunkedLoops& loops);
  // Where the collapse of the edge (pa, pb) with quadric q puts its survivor.
  Vec3 place(const Quadric& q, const Vec3& pa, const Vec3& pb) const;
  // The minimiser of `total` among the placements that meet the constraints the options ask
  // for (placement_constraints.h); false where there is none. `total` is q plus the star's
  // planes (QuadricOptions::star_planes_weight).
  bool place_on_constraints(const CollapseMesh& mesh, VertexId a, VertexId b, const Quadric& q,
                            Quadric& total, Vec3& out, StarTermsScratch& scratch) const;
  // evaluate and evaluate_seam without counting, with the working memory given: what a
  // costing view calls too.
  bool cost(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
            Costing costing, StarTermsScratch& scratch) const;
  // A seam pair's summed quadric, the lesser id's first: the same bits whichever end is vs.
  Quadric pair_quadric(VertexId a, VertexId b) const;
  bool cost_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                 CollapseCandidate& out) const;
  // evaluate_seam_at without counting; `sums`: working memory, a quadric per pair.
  void cost_seam_at(std::span<const SeamPair> pairs, std::span<const Vec3> places,
                    std::span<SeamCosting> out, std::vector<Quadric>& sums) const;
  friend class QuadricCostingView;

  uint64_t costings_ = 0;
  std::vector<uint8_t> locked_;
  QuadricOptions options_;
  std::vector<Quadric> quadrics_;
  StarTermsScratch star_scratch_;   // place_on_constraints's working memory
  std::vector<Quadric> seam_sums_;  // cost_seam_at's
};

}  // namespace parapm
