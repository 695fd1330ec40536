// Selective refinement of a Progressive Mesh (Hoppe 96, section 5): walk the splits in order
// and apply split i only where the caller wants detail, e.g. inside the view frustum.
//
// Split i is applied when, in the mesh refined so far:
//  1. vs, vl and vr (those that are not kNoId) are present: a base vertex is always present,
//     vertex n0 + j is present when split j was applied (in PM 96 nothing is ever removed,
//     so "present" is "created"); otherwise it is skipped as absent;
//  2. the split fits: vl and vr are adjacent to vs and the fan rule (fan_mesh.cpp) finds its
//     faces; otherwise it is skipped as inapplicable (earlier skips changed the neighbourhood);
//  3. refine(vs, current position of vs) returns true; otherwise skipped by the predicate.
// Applying it sets vs to vs_after and creates vt = n0 + i at vt_after, with its new wedges and
// wedge changes. A predicate that always says yes gives the full-resolution mesh exactly (same
// numbering); one that always says no gives the base mesh.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "mesh/mesh.h"
#include "pm/progressive_mesh.h"

namespace parapm {

struct SelectiveRefinement {
  Mesh mesh;  // present vertices in PM id order, faces in the order they were created
  std::vector<VertexId> pm_vertex;  // per vertex of `mesh`, its PM vertex id
  size_t applied = 0;
  size_t skipped_absent = 0;
  size_t skipped_by_predicate = 0;
  size_t skipped_inapplicable = 0;
};

// `refine` receives the PM id of vs and its current position; it is called only for splits
// that passed rules 1 and 2, in split order. Throws Error(kInvalidInput) when the PM is
// corrupt (ids out of range); never for a split that merely does not fit.
using RefinePredicate = std::function<bool(VertexId vs, const Vec3& position)>;
SelectiveRefinement selectively_refine(const ProgressiveMesh& pm, const RefinePredicate& refine);

}  // namespace parapm
