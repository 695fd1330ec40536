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

}  // namespace parapm
