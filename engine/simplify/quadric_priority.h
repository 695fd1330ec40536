// The quadric priority module: Garland & Heckbert 97 plane quadrics, area weighted, with
// boundary-preserving planes along open edges, optimal placement with a fallback.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

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
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b,
                CollapseCandidate& out) const override;
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done, const EdgeFaces& edge) override;

 private:
  std::vector<uint8_t> locked_;
  QuadricOptions options_;
  std::vector<Quadric> quadrics_;
};

}  // namespace parapm
