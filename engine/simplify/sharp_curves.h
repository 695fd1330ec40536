// E_disc of Hoppe 96 (section 4.4): the discontinuity curves of the mesh (sharp edges: open
// boundaries and the rims of double-sided sheets (back_to_back.h), creases whose dihedral
// angle exceeds a threshold, attribute seams) sampled on the input, each sample measured
// against the curves of the current mesh, and the rule that flags a collapse changing the
// curves' topology (priced by the energy, not forbidden).
//
// The curves are kept as a sharp-neighbour list per vertex; a collapse moves vt's sharp
// edges to vs (the edge (vs, vt) itself disappears). A sample tracks the sharp edge it
// projects onto and is listed at both of that edge's ends.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "simplify/collapse_mesh.h"
#include "simplify/module_state.h"
#include "simplify/vec_math.h"

namespace parapm {

struct SharpEdgeOptions {
  // Sharp when the face normals differ by more; 180: no creases (the default: the star's planes
  // keep them, docs/DECISIONS.md, "No crease curves by default").
  double crease_angle_degrees = 180;
  bool boundaries = true;  // open boundaries, and edges whose faces lie back to back
  bool seams = true;       // edges across which a corner's wedge changes
  // A crease of fewer edges than min_crease_edges and shorter than long_crease_diagonals of
  // the bounding-box diagonal is a scan's noise, not kept (1: every crease is); the length
  // clause keeps a coarse mesh's few but long creases (docs/DECISIONS.md, "Creases of fewer than 8
  // edges and shorter than 5% of the diagonal are noise").
  uint32_t min_crease_edges = 8;
  double long_crease_diagonals = 0.05;
};

// Every sharp edge of the mesh once, as (a, b) with a < b (short creases dropped, see above).
std::vector<std::pair<VertexId, VertexId>> find_sharp_edges(const CollapseMesh& mesh,
                                                            const SharpEdgeOptions& options);
// The same edges, the faces' twins and the faces read in `loops`' chunks.
std::vector<std::pair<VertexId, VertexId>> find_sharp_edges(const CollapseMesh& mesh,
                                                            const SharpEdgeOptions& options,
                                                            ChunkedLoops& loops);

class SharpCurves {
 public:
  // One sample at each vertex on a curve and one at the midpoint of every sharp edge.
  void initialize(const CollapseMesh& mesh, const SharpEdgeOptions& options);
  void initialize(const CollapseMesh& mesh, const SharpEdgeOptions& options, ChunkedLoops& loops);
  // No curves at all (E_disc off), sized for the mesh.
  void initialize_empty(const CollapseMesh& mesh);

  size_t sample_count() const { return samples_.size(); }
  // Whether the whole mesh has curve samples (a job may hold none of them).
  bool has_samples() const { return total_samples_ > 0; }
  size_t sharp_edge_count() const { return edge_count_; }
  const std::vector<VertexId>& sharp_neighbors(VertexId v) const {
    return neighbors_.empty() ? no_neighbors_ : neighbors_[v];
  }
  bool on_curve(VertexId v) const { return !sharp_neighbors(v).empty(); }
  bool is_sharp(VertexId a, VertexId b) const;
  // Hoppe 96's test: collapsing {a, b} changes the curves' topology when both ends are on
  // curves but the edge is not sharp (two curves would touch), when both ends are curve
  // corners or ends (degree != 2: merging them changes the graph), or when a and b share a
  // sharp neighbour (a sharp triangle would fold into a double edge).
  bool changes_topology(VertexId a, VertexId b) const;

  // The samples a collapse of {a, b} moves, and the curve segments (v, x) after it: x runs
  // over the sharp neighbours of a and b other than a and b. Late collapses move thousands of
  // samples along a long curve: beyond `max_samples`, about one in k stands for k
  // (sample_thinning.h; project() and distance_sq() weigh them), which keeps an evaluation
  // bounded. The performed collapse (collapsed()) moves every sample. A costing's own scratch:
  // costings on several threads each gather into their own.
  struct Gathered {
    std::vector<uint32_t> samples;
    double weight = 1;           // how many samples each gathered one stands for
    std::vector<VertexId> ends;  // the x of the segments (v, x)
    std::vector<Vec3> end_positions;
    size_t size() const { return samples.size(); }
  };
  void gather(VertexId a, VertexId b, const CollapseMesh& mesh, size_t max_samples,
              Gathered& out) const;
  struct Fit {
    double distance_sq = 0, max_distance_sq = 0, a = 0;
    Vec3 b{};      // as EnergyPriority's: sum of b0^2 and of b0 (x - (1 - b0) x_other)
    double c = 0;  // and of |x - (1 - b0) x_other|^2
    double model_at(const Vec3& w) const { return c - 2 * dot(b, w) + a * dot(w, w); }
  };
  // The gathered samples projected onto the gathered segments with the moved vertex at v
  // (onto v itself when no segment is left).
  Fit project(const Gathered& gathered, const Vec3& v) const;
  // Their distances before the collapse.
  double distance_sq(const Gathered& gathered) const;

  // Updates the curves and re-projects the samples after the collapse of vt into vs;
  // returns the largest distance squared among the samples it moved.
  double collapsed(VertexId vs, VertexId vt, const CollapseMesh& mesh);

  // State export/import for the parallel construction (module_state.h): the curves at
  // `vertices` (the module's ids; out.vertices lists them written through `to`) go to out's
  // sharp and listed lists, the samples listed there (with their every end translating) to
  // out.samples. import_local builds the curves of a job's mesh from such a state (local ids)
  // instead of initialize(); import_global overwrites the state's vertices and its samples (or
  // only those of `written`: indices into state.samples; their positions stay this module's:
  // samples never move), after check_global, which throws
  // Error(kInvalidInput) for a state whose lists or ids do not fit (it changes nothing).
  void export_state(const std::vector<VertexId>& vertices, const IdTranslation& to,
                    EnergyState& out) const;
  void import_local(const CollapseMesh& mesh, const EnergyState& state);
  void check_global(const EnergyState& state) const;
  void import_global(const EnergyState& state, const std::vector<uint32_t>* written = nullptr);

  // Observers for tests: a sample's position, distance squared and the edge it is on.
  const Vec3& sample_position(size_t i) const { return samples_[i].position; }
  double sample_distance_sq(size_t i) const { return samples_[i].distance_sq; }
  std::pair<VertexId, VertexId> sample_edge(size_t i) const {
    return {samples_[i].u, samples_[i].w};
  }

 private:
  struct Sample {
    Vec3 position{};
    double distance_sq = 0;
    VertexId u = kNoId, w = kNoId;  // the sharp edge it projects onto (w = kNoId: onto u)
  };
  void add_sharp(VertexId a, VertexId b);
  void unlist(VertexId v, uint32_t id);
  const std::vector<uint32_t>& listed_at(VertexId v) const {
    return listed_at_.empty() ? no_samples_ : listed_at_[v];
  }
  // Sizes the per-vertex lists for the mesh (before any is written).
  void make_lists();

  std::vector<Sample> samples_;
  size_t vertex_capacity_ = 0;
  // Per vertex, or empty where the module has no sharp edge and no sample (a closed mesh
  // without seams: 48 B per vertex saved); a collapse never makes the first one.
  std::vector<std::vector<VertexId>> neighbors_;
  std::vector<std::vector<uint32_t>> listed_at_;  // per vertex: samples on its sharp edges
  static inline const std::vector<VertexId> no_neighbors_{};
  static inline const std::vector<uint32_t> no_samples_{};
  size_t edge_count_ = 0;
  size_t total_samples_ = 0;
  std::vector<uint32_t> sample_id_;  // a job's: per sample, the master's id (empty: identity)
  std::vector<uint32_t> moved_;      // collapsed()'s scratch: the samples it moves
};

}  // namespace parapm
