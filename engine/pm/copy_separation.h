// How far apart the repair's copies of one input vertex are at a level of detail. The repair
// splits a non-manifold input vertex into copies, one per sheet meeting there
// (ProgressiveMesh::vertex_copies); by default the copies move and leave together (seam
// collapses, simplify/copy_groups.h), so the sheets meet at every level but inside one seam
// collapse's records and for a copy left behind in a part too small to shrink, while with
// SimplifyOptions::free_copies they simplify like any vertex and the sheets may part at coarse
// levels (cracks). This measures the parting.
#pragma once

#include <cstddef>

#include "pm/progressive_mesh.h"

namespace parapm {

struct CopySeparation {
  size_t pairs = 0;   // (copy, original) pairs of the PM
  size_t parted = 0;  // of them, at different positions in the level
  double max = 0;     // the largest distance between a copy and its original, model units
  double mean = 0;    // over all pairs (0 for those that met)
};

// At level `level` (0: the base mesh) a full-resolution vertex is stood for by itself when
// present, else by the vertex its split came from (VertexSplit::vs), recursively; the distance
// of a pair is that between its two stand-ins' positions in the level. Throws
// Error(kInvalidInput) when level exceeds the split count.
CopySeparation copy_separation(const ProgressiveMesh& pm, size_t level);

}  // namespace parapm
