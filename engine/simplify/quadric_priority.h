// The quadric priority module: Garland & Heckbert 97 plane quadrics, area weighted, with
// boundary-preserving planes along open edges, optimal placement with a fallback.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "simplify/module_state.h"
#include "simplify/modules.h"
#include "simplify/quadric.h"

namespace parapm {

struct QuadricOptions {
  // Weight of the plane through a boundary edge, perpendicular to its face, relative to the
  // face planes (it is multiplied by the squared edge length to have area units).
  double boundary_weight = 4.0;
  bool round_to_float = false;  // place vertices on float32 coordinates (exact PM storage)
};

class QuadricPriority : public PriorityModule {
 public:
  QuadricPriority(std::vector<uint8_t> locked, QuadricOptions options)
      : locked_(std::move(locked)), options_(options) {}
  std::string name() const override { return "quadric"; }
  void initialize(const CollapseMesh& mesh) override;
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override;  // (both costings alike: it is cheap)
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) override;
  uint64_t costings() const override { return costings_; }

  // State export/import for the parallel construction (module_state.h). export_local: the
  // quadrics of a job's vertices (maps: its local -> global ids), in its local ids.
  // import_local: a job's module from that state, instead of initialize(). export_global: the
  // quadrics of the vertices marked in `changed` (per local vertex: those the job's collapses
  // moved or removed; the others' quadrics are the master's), in global ids.
  // import_global: the master overwrites those vertices' quadrics.
  QuadricState export_local(const IdMaps& maps) const;
  void import_local(const CollapseMesh& mesh, const QuadricState& state);
  QuadricState export_global(const IdMaps& maps, const std::vector<uint8_t>& changed) const;
  void import_global(const QuadricState& state);
  // Before import_global of several jobs' states side by side (job_state.h): throws
  // Error(kInvalidInput) unless every vertex of `state` is in range and, with vertex_subset,
  // the subset's.
  void check_global(const QuadricState& state, uint32_t subset,
                    const std::vector<uint32_t>* vertex_subset) const;
  const Quadric& quadric(VertexId v) const { return quadrics_[v]; }

 private:
  uint64_t costings_ = 0;
  std::vector<uint8_t> locked_;
  QuadricOptions options_;
  std::vector<Quadric> quadrics_;
};

}  // namespace parapm
