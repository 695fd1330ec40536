// The collapse engine's plug-in points, after OpenMesh's Decimater: constraint modules veto
// a collapse, one priority module costs it and places the surviving vertex. A module's
// per-vertex state (quadrics, sample points) belongs to the module.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "simplify/collapse_mesh.h"

namespace parapm {

class ThreadTeam;

// The collapse of edge (vs, vt): vt is merged into vs, which moves to `position`.
struct CollapseCandidate {
  VertexId vs = kNoId;
  VertexId vt = kNoId;
  Vec3 position{};
  double cost = 0;   // priority: smaller collapses first; units are the module's own
  double error = 0;  // geometric error of the collapse in model units (for cutting a PM)
  // One of a seam collapse's collapses (copy_groups.h): vs and vt may be locked copies.
  bool seam = false;
  // Set by the priority module: this costing is what a kPerform costing of the edge on the
  // mesh as it is gives (a kQueue costing may be exactly that: the simplifier then does not
  // cost the edge again for its collapse).
  bool as_performed = false;
  Vec3 vs_before{};  // where vs was: set when the collapse is performed (or replayed)
  // Filled by PriorityModule::collapsed when the module changed wedge values (E_scalar): the
  // wedges and their new values, floats_per_wedge each.
  std::vector<WedgeId> changed_wedges;
  std::vector<float> changed_values;
};

// What a costing is for. kPerform: the collapse the engine is about to perform, whose placement
// and cost go into the PM. kQueue: a key for the priority queue, which a module may estimate
// more cheaply: an edge is costed again, with kPerform, when it reaches the top. Most queued
// costs are never used (a neighbouring collapse changes the edge first), so the estimate is
// where a costly metric saves most of its time. kEstimate: a cost for a sample of the mesh's
// costs (the parallel build's water level, round_shares.h), read only for its cost: kQueue's
// key, or where that key is a loose lower bound (the quadric's where its A is singular), one
// near the cost kPerform would give.
enum class Costing { kPerform, kQueue, kEstimate };

// One collapse of a seam collapse (Simplifier::join_copies): vt into vs.
struct SeamPair {
  VertexId vs = kNoId;
  VertexId vt = kNoId;
};

// A seam collapse costed at one place (PriorityModule::evaluate_seam_at).
struct SeamCosting {
  bool placed = false;  // every pair costed, their summed cost finite
  // The first pair's costing, with the pairs' summed cost and their largest error.
  CollapseCandidate candidate;
};

// An edge to cost, and what its costing gave (PriorityModule::evaluate_each).
struct EdgeCosting {
  VertexId a = kNoId, b = kNoId;
  bool placed = false;  // evaluate()'s answer
  CollapseCandidate candidate;
};

class PriorityModule {
 public:
  virtual ~PriorityModule() = default;
  virtual std::string name() const = 0;
  virtual void initialize(const CollapseMesh& mesh) = 0;
  // initialize(), its passes over the mesh cut into `loops`' chunks, which may run side by side:
  // the same state, whatever the chunking. The parallel build's set-up runs it on its pool,
  // beside the first partition. Default: initialize(), one thread's work (so a wrapper
  // initialises as its own initialize() does).
  virtual void initialize_in_chunks(const CollapseMesh& mesh, ChunkedLoops& /*loops*/) {
    initialize(mesh);
  }
  // Costs the collapse of edge {a, b}, choosing which end survives and where. Returns false
  // when the collapse cannot be placed (the edge is then left alone). Not const: a costing may
  // write the module's working memory and caches (a module serves one thread at a time).
  virtual bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                        Costing costing) = 0;
  // evaluate() of each edge, with the answers and the module's state after as if they were
  // costed one after the other in order (a costing changes no state but caches). A module may
  // cost them side by side (the energy on its team, use_team). Default: one after the other.
  virtual void evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                             Costing costing) {
    for (EdgeCosting& e : edges) e.placed = evaluate(mesh, e.a, e.b, e.candidate, costing);
  }
  // Costs the collapse of vt into vs, whether or not either end is locked: one collapse of a
  // seam collapse (copy_groups.h). vs goes to *at when given, else where the module places it
  // best. false: it cannot be costed (the default: a module that takes no part in seams).
  virtual bool evaluate_seam(const CollapseMesh&, VertexId /*vs*/, VertexId /*vt*/,
                             const Vec3* /*at*/, CollapseCandidate&, Costing) {
    return false;
  }
  // A seam collapse's pairs costed at each of `places` (out: one per place): evaluate_seam of
  // every pair in order with vs at the place, summed. A place is not placed where a pair cannot
  // be costed or the sum is not finite. Default: evaluate_seam pair by pair, place by place (a
  // place stops at its first refusal); a module may share its work between the places.
  virtual void evaluate_seam_at(const CollapseMesh& mesh, std::span<const SeamPair> pairs,
                                std::span<const Vec3> places, Costing costing,
                                std::span<SeamCosting> out) {
    cost_seam_pair_by_pair(mesh, pairs, places, costing, out);
  }
  // Called after the mesh performed `done`, to update the module's state. `edge` names the two
  // faces the collapse removed (now dead); done.vs_before where vs was (vt keeps its position
  // in the mesh). The module may refine done.error with what it learns from the performed
  // collapse (the record takes the refined value).
  virtual void collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                         const EdgeFaces& edge) = 0;
  // Whether a costing costs far more than checking an edge's topological rules (the energy's
  // take microseconds, a link condition a fraction of one). Then the simplifier checks those
  // rules before it costs an edge on top of the queue or one vetoed before whose star changed:
  // one they veto again waits among the vetoed edges, uncosted, instead of being costed twice
  // (queue key, then on top) only to be vetoed. Not before every costing: most edges pass, and
  // the checks would cost more than the costings they save (decisions/notebook-2026-11.md,
  // "Vetoed edges"). The parallel build carries only a costly module's queue keys from round
  // to round (edge_keys.h): for a cheap one, carrying costs more than costing again.
  virtual bool costly() const { return false; }
  // Whether an edge's queue costing (kQueue) reads only its two ends' own state (their
  // positions and what the module keeps per vertex), not their stars': then its key stays
  // while neither end changes, however the faces around them do, and the simplifier may cost
  // an edge's collapse when it queues it (Simplifier::queue_checked). Default: false.
  virtual bool queue_key_of_ends_only() const { return false; }
  // Whether an edge whose queue costing (kQueue) is placed is placed by the costing for its
  // collapse (kPerform) too, on the same mesh: then the simplifier may check the rules that
  // read the edge alone before that costing (Simplifier::vetoed_when_queued), and a veto is
  // what the costing first would have come to. Default: false.
  virtual bool placed_when_queued_is_placed() const { return false; }
  // The edges this module has costed itself so far (its evaluate calls; a wrapper's own
  // answers, such as a carried key or a subset rule's refusal, are not counted). Summed over a
  // build's modules it is the build's work in costings, the figure the parallel build's work
  // is compared with the sequential one's by, free of the machine's timing noise.
  virtual uint64_t costings() const { return 0; }
  // Frees what the module can rebuild when it next costs an edge (caches), without changing
  // any costing: the parallel build's master while the jobs of a round run.
  virtual void release_caches() {}
  // For costing edges on several threads at once (the parallel build's round samples): a
  // module whose evaluate and evaluate_seam cost as this one's do, reading this one's state,
  // with working memory and a costings count of its own; it performs nothing (collapsed
  // throws). It lives while this one does and this one changes nothing meanwhile. Null (the
  // default, and a wrapper's): this module costs on one thread only.
  virtual std::unique_ptr<PriorityModule> costing_view() const { return nullptr; }
  // Threads the module may use within collapsed() for work that splits into independent
  // pieces (the energy's point projections), with the same results as on one thread; null
  // (the default): none. The team outlives the module, or its use ends with use_team(nullptr).
  virtual void use_team(ThreadTeam* /*team*/) {}
  // A hint: the edges from `from` to each of `to` are costed next. A module whose costings
  // read per-vertex state scattered in memory may start loading it now, so that the loads
  // overlap instead of waiting one after another. No effect on any result (the default: none).
  virtual void will_cost(VertexId /*from*/, std::span<const VertexId> /*to*/) const {}

 protected:
  // evaluate_seam_at's default: through this module's evaluate_seam.
  void cost_seam_pair_by_pair(const CollapseMesh& mesh, std::span<const SeamPair> pairs,
                              std::span<const Vec3> places, Costing costing,
                              std::span<SeamCosting> out) {
    CollapseCandidate other_pair;  // the costing of a pair after the first
    for (size_t k = 0; k < places.size(); ++k) {
      SeamCosting& s = out[k];
      s.candidate = CollapseCandidate{};
      s.placed = false;
      double cost = 0, error = 0;
      bool each = true;
      for (size_t i = 0; i < pairs.size() && each; ++i) {
        CollapseCandidate& c = i == 0 ? s.candidate : other_pair;
        each = evaluate_seam(mesh, pairs[i].vs, pairs[i].vt, &places[k], c, costing);
        cost += c.cost;
        error = std::max(error, c.error);
      }
      if (!each) continue;
      s.candidate.cost = cost;
      s.candidate.error = error;
      s.candidate.seam = true;
      s.placed = std::isfinite(cost);
    }
  }
};

// A module wrapped around another (a restriction, a memo, a step left out): forwards every
// call to `inner`; a wrapper overrides only what it changes, so that what the inner module
// tells the engine (its name, costly()) passes through every layer.
class PriorityWrapper : public PriorityModule {
 public:
  explicit PriorityWrapper(PriorityModule& inner) : inner_(inner) {}
  std::string name() const override { return inner_.name(); }
  bool costly() const override { return inner_.costly(); }
  bool queue_key_of_ends_only() const override { return inner_.queue_key_of_ends_only(); }
  bool placed_when_queued_is_placed() const override {
    return inner_.placed_when_queued_is_placed();
  }
  uint64_t costings() const override { return inner_.costings(); }
  void release_caches() override { inner_.release_caches(); }
  void use_team(ThreadTeam* team) override { inner_.use_team(team); }
  void will_cost(VertexId from, std::span<const VertexId> to) const override {
    inner_.will_cost(from, to);
  }
  void initialize(const CollapseMesh& mesh) override { inner_.initialize(mesh); }
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    return inner_.evaluate(mesh, a, b, out, costing);
  }
  bool evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                     CollapseCandidate& out, Costing costing) override {
    return inner_.evaluate_seam(mesh, vs, vt, at, out, costing);
  }
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                 const EdgeFaces& edge) override {
    inner_.collapsed(mesh, done, edge);
  }
  // (evaluate_each and evaluate_seam_at are not forwarded: a wrapper whose evaluate() or
  // evaluate_seam() changes answers costs each edge or pair through them, unless it overrides
  // these too, with evaluate_picked or cost_seam_pair_by_pair.)

 protected:
  // inner.evaluate_each of the edges `pick(edge)` is true of, in their order; `pick` may
  // answer the others itself (each starts unplaced). Returns the indices of those costed.
  template <typename Pick>
  std::span<const size_t> evaluate_picked(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                                          Costing costing, Pick&& pick) {
    picked_.clear();
    picked_index_.clear();
    for (size_t i = 0; i < edges.size(); ++i) {
      edges[i].placed = false;
      if (!pick(edges[i])) continue;
      picked_.push_back(std::move(edges[i]));
      picked_index_.push_back(i);
    }
    inner_.evaluate_each(mesh, picked_, costing);
    for (size_t k = 0; k < picked_.size(); ++k) edges[picked_index_[k]] = std::move(picked_[k]);
    return picked_index_;
  }

  PriorityModule& inner_;

 private:
  std::vector<EdgeCosting> picked_;  // evaluate_picked's
  std::vector<size_t> picked_index_;
};

class ConstraintModule {
 public:
  virtual ~ConstraintModule() = default;
  virtual std::string name() const = 0;
  virtual void initialize(const CollapseMesh&) {}
  // `edge` holds the faces on the edge (vs, vt) as CollapseMesh::edge_faces(vs, vt).
  virtual bool allows(const CollapseMesh& mesh, const CollapseCandidate& candidate,
                      const EdgeFaces& edge) const = 0;
  // After allows() answered false: a face whose fold alone made that answer
  // (collapse_folds_face), which the simplifier tests first when it costs the edge again
  // (most vetoed edges are vetoed again, by the same face); kNoId (the default): none.
  virtual FaceId folded_face() const { return kNoId; }
  // Whether the answer depends on the edge {vs, vt} only: not on which end survives nor on
  // the placement. Such a rule can veto an edge before any costing.
  virtual bool topological() const { return false; }
  // Whether the answer depends only on the candidate and on the faces around its ends and
  // their corners' positions, which stay as they are while no collapse changes the edge's star
  // (Simplifier: a requeued candidate kept with its star unchanged is not asked again).
  virtual bool star_local() const { return false; }
  // For a seam collapse (Simplifier::join_copies): removes from `collapses` those this rule
  // would veto once the ones before them were made because their part is at its smallest form
  // (the component minimum); such a copy stays where it is. A rule that vetoes for other
  // reasons removes none: its veto stops the whole seam collapse.
  virtual void drop_too_small(const CollapseMesh&, std::vector<SeamPair>&) const {}
  virtual void collapsed(const CollapseMesh&, const CollapseCandidate&) {}
};

// The legality rules every collapse obeys (Hoppe 96 section 3, and METHOD.md section 1), in
// the order they are checked, cheapest first:
//   locked vertices: a vertex the repair step duplicated is moved or removed only by a seam
//     collapse (CollapseCandidate::seam; copy_groups.h);
//   minimum size: a closed component keeps at least 4 vertices (a tetrahedron), an open one
//     at least 3 (a triangle); with `components_may_vanish`, an open component may also
//     collapse its last triangle away (its last vertices stay, faceless), unless it is the one
//     of the largest area or has a vertex where another component has one (vertices flagged in
//     `on_membrane`, a membrane's (copy_groups.h), do not count: a membrane may vanish);
//   boundary: an edge between two boundary vertices must itself be a boundary edge;
//   link condition: vs and vt share no neighbour other than the apexes of the edge's faces;
//   geometry: no remaining face around vs or vt flips its normal or becomes degenerate.
// `components`, when given, are the mesh's connected components as connected_components
// numbered them on this mesh or on it before some legal collapses (which neither merge nor split
// components): the minimum-size rule then counts the live vertices per component instead of
// finding the components again (an O(faces) union-find over the whole capacity, which the
// parallel build's band passes and final pass would each pay on the whole mesh).
std::vector<std::unique_ptr<ConstraintModule>> standard_constraints(
    const std::vector<uint8_t>& locked,
    std::shared_ptr<const std::vector<uint32_t>> components = {},
    bool components_may_vanish = false, std::vector<uint8_t> on_membrane = {});

// Whether face f, alive, around an end the candidate moves and not on the edge, folds in its
// collapse (face_fold.h): then the standard geometry rule vetoes the candidate.
bool collapse_folds_face(const CollapseMesh& mesh, const CollapseCandidate& candidate,
                         const EdgeFaces& edge, FaceId f);

// The standard rules that read only the faces around the edge's ends (boundary, link
// condition, geometry): what a seam collapse's trial on a copy of those faces checks
// (Simplifier::join_copies).
std::vector<std::unique_ptr<ConstraintModule>> neighbourhood_constraints();

}  // namespace parapm
