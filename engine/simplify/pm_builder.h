// Turns the simplifier's collapse records and the mesh they leave into a Progressive Mesh:
// the surviving mesh becomes the base mesh, the records reversed become the vertex splits,
// and every id is renumbered to the PM's streaming order (progressive_mesh.h).
#pragma once

#include <span>
#include <vector>

#include "mesh/repair.h"
#include "pm/progressive_mesh.h"
#include "simplify/collapse_mesh.h"
#include "simplify/simplifier.h"
#include "util/chunked_loops.h"

namespace parapm {

struct PmBuildOptions {
  bool keep_order = false;  // store the input's vertex and face order (--keep-order)
  // Where the passes over the vertices, faces and splits run in chunks side by side (the same
  // PM; the wedges' numbering, in order of first use, stays one pass); null: on the calling
  // thread.
  ChunkedLoops* loops = nullptr;
};

// The mesh a build leaves when its last collapses were made on a compact copy of its live part
// (the parallel build's final pass, parallel/live_pass.h), not on `whole`: the copy's state
// for the vertices and faces it holds, `whole`'s for the others.
struct PartlyCopiedMesh {
  const CollapseMesh& whole;
  const CollapseMesh& copy;
  std::span<const uint32_t> vertex_in_copy;  // per vertex of `whole`: its copy's id, or kNoKey
  std::span<const uint32_t> face_in_copy;    // per face of `whole`: the same
  std::span<const VertexId> vertex_of_copy;  // per vertex of the copy: its id in `whole`

  const Vec3& position(VertexId v) const {
    const uint32_t c = vertex_in_copy[v];
    return c == kNoKey ? whole.position(v) : copy.position(c);
  }
  // (a face dead on the whole mesh died before the copy was made; a live one is in the copy)
  bool face_alive(FaceId f) const {
    return whole.face_alive(f) && copy.face_alive(face_in_copy[f]);
  }
  Triangle face(FaceId f) const {
    const uint32_t c = face_in_copy[f];
    if (c == kNoKey) return whole.face(f);
    const Triangle& t = copy.face(c);
    return {vertex_of_copy[t[0]], vertex_of_copy[t[1]], vertex_of_copy[t[2]]};
  }
};

// `repaired` is the mesh the simplifier started from; `final_mesh` the CollapseMesh after
// `records` were performed on it, in order.
ProgressiveMesh build_pm_from_collapses(const RepairedMesh& repaired,
                                        const CollapseMesh& final_mesh,
                                        const std::vector<CollapseRecord>& records,
                                        const PmBuildOptions& options);
// The same, the records read where they lie (the parallel build's stay in their subsets' lists).
ProgressiveMesh build_pm_from_collapses(const RepairedMesh& repaired,
                                        const CollapseMesh& final_mesh,
                                        std::span<const CollapseRecord* const> records,
                                        const PmBuildOptions& options);

// The same, the last collapses made on a compact copy of the live part.
ProgressiveMesh build_pm_from_collapses(const RepairedMesh& repaired,
                                        const PartlyCopiedMesh& final_mesh,
                                        std::span<const CollapseRecord* const> records,
                                        const PmBuildOptions& options);

}  // namespace parapm
