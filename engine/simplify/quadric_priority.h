// The quadric priority module: Garland & Heckbert 97 plane quadrics, area weighted, with
// boundary-preserving planes along open edges, optimal placement with a fallback.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "simplify/module_state.h"
#include "simplify/modules.h"
#include "simplify/quadric.h"
#include "simplify/simplifier.h"

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
  bool evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                     CollapseCandidate& out, Costing costing) override;
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) override;
  uint64_t costings() const override { return costings_; }

  // State transfer for the parallel construction (module_state.h). export_local: the
  // quadrics of a job's vertices (maps: its local -> global ids), in its local ids.
  // import_local: a job's module from that state, instead of initialize(). A job returns no
  // quadrics: its collapses change them only by collapsed() (Q_vs += Q_vt), so the master
  // follows a job from its records (follow_records), exactly and at the cost of a copy.
  QuadricState export_local(const IdMaps& maps) const;
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

 private:
  // Where the collapse of the edge (pa, pb) with quadric q puts its survivor.
  Vec3 place(const Quadric& q, const Vec3& pa, const Vec3& pb) const;

  uint64_t costings_ = 0;
  std::vector<uint8_t> locked_;
  QuadricOptions options_;
  std::vector<Quadric> quadrics_;
};

}  // namespace parapm
