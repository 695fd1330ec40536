// The non-conflict rule of the parallel construction (METHOD.md section 4, weakness 2: the
// 1999 workers' border collapses could interact across the cut).
//
// Rule. Subset S may collapse the edge (vs, vt) only if vs, vt and every vertex adjacent to
// either of them are owned by S; equivalently, vs and vt are "free": owned, with no neighbour
// owned by another subset. Moreover, when the connected component of vs in S's job also
// holds halo vertices (it continues outside S), S keeps more than 4 of its own vertices in it.
//
// Proof that the subsets' collapses never conflict. Let a collapse c of S read or change
// state X. The collapse removes the faces on its edge and renames vt in the faces around vt,
// moves vs: every face it changes has vs or vt as a corner, so all three corners are owned
// by S ("S-faces"). Its legality (link condition, boundary rule, face geometry) and its cost
// read the faces around vs and vt (S-faces), the positions of their corners (owned by S),
// the fans of those corners (for boundary status, sharp edges and quadrics: faces around an
// owned vertex, which are S-faces or "mixed" faces with a vertex of another subset), and the
// module state attached to those faces and vertices (sample points, quadrics, wedges).
//  (1) A mixed face never changes during a round: changing it needs a corner of it as vs or vt,
//      and each of its owned corners has a foreign neighbour, so is not free in its subset.
//  (2) So every face or vertex a collapse of S changes is an S-face or an S-vertex, which no
//      other subset T reads (T reads T-faces, T-vertices and mixed faces only). The module
//      state moves with the same faces (points re-project onto faces of the star; a wedge
//      changed is used by corners at vs only, and a wedge's corners always share one vertex).
//  (3) The free set is static in a round: a vertex gains neighbours only as vs (vt's, all
//      owned) or as a neighbour of vt (vs, owned), so a free vertex stays free and a vertex
//      next to a foreign vertex keeps that neighbour (neither can be removed).
// Hence the state each collapse of S reads is the same whether S runs alone on its job or
// the subsets' sequences are interleaved in any order that keeps each subset's own order:
// every merged sequence replays on the whole mesh with the faces and apexes each subset saw
// (checked on every replay, collapse_merge.h). The component clause keeps the global rule
// "a closed component keeps more than 4 vertices, an open one more than 3": whatever other
// subsets do, the component still holds S's live vertices of it, more than 4.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "mesh/mesh.h"
#include "simplify/collapse_mesh.h"
#include "simplify/modules.h"
#include "util/chunked_loops.h"

namespace parapm {

// Per local vertex of `mesh`: 1 when it is owned and all its neighbours are owned.
std::vector<uint8_t> free_vertices(const Mesh& mesh, const std::vector<uint8_t>& owned);

// The faces of `mesh` a job can remove: those with at least two free corners (the third, a
// neighbour of a free vertex, is owned). A face with two corners next to another subset has no
// edge with two free ends.
uint64_t removable_faces(const Mesh& mesh, const std::vector<uint8_t>& free);

// Per vertex of the whole `mesh`, 1 when it is "bound" in the partition `vertex_subset` (one
// entry per vertex): a neighbour of it lies in another subset, so it is not free and no job
// moves it this round. A vertex with a neighbour in another subset shares a face with it (the
// mesh is manifold after the repair), so a face with corners in two subsets marks all three.
// With `loops`, over the faces in its chunks (null: on the calling thread).
std::vector<uint8_t> bound_vertices(const CollapseMesh& mesh,
                                    const std::vector<uint32_t>& vertex_subset,
                                    ChunkedLoops* loops = nullptr);

// The live faces that no subset can remove in the round whose bound vertices are `bound`
// (bound_vertices): those with two or more bound corners, removable_faces' complement, counted
// without extracting the jobs. With `loops`, in its chunks.
uint64_t border_faces(const CollapseMesh& mesh, const std::vector<uint8_t>& bound,
                      ChunkedLoops* loops = nullptr);

// The rule as a constraint module, checked on every pop (after the standard constraints).
// It tests the adjacency of vs and vt on the present mesh, not the static free flags, so that
// it checks the rule as stated.
std::unique_ptr<ConstraintModule> make_subset_constraint(std::vector<uint8_t> owned);

// Wraps the subset's priority module so that an edge without two free ends is never costed
// nor queued (by (3) above it can never become collapsible during the round): the job does
// no work on its border. Forwards everything else. (The job's cost ceiling is the simplifier's:
// SimplifierLimits::max_cost.)
std::unique_ptr<PriorityModule> make_subset_priority(PriorityModule& inner,
                                                     std::vector<uint8_t> free_vertex);

}  // namespace parapm
