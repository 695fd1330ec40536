// Choosing a level of detail of a Progressive Mesh, and extracting it.
//
// Level k is the base mesh after splits 0..k-1 (0 <= k <= n, n = pm.splits.size(); level n
// is the full-resolution mesh). Its face count is base faces + the new faces of splits
// 0..k-1, which is known without applying anything.
//
// Its error is the error bound of the coarse mesh it is: error(k) = splits[k].error for
// k < n (the split that would refine it next records the bound of the level it leaves,
// progressive_mesh.h), and error(n) = 0. Errors never increase with k (validate_pm), so
// "cut at error E" = apply every split whose error is > E = the smallest k with
// error(k) <= E.
#pragma once

#include <cstddef>

#include "mesh/mesh.h"
#include "pm/progressive_mesh.h"

namespace parapm {

// Face count of level k; throws Error(kInvalidInput) when k > n.
size_t face_count_at_level(const ProgressiveMesh& pm, size_t level);

// The largest level whose face count is <= max_faces. When even the base mesh has more
// faces, returns 0 (the coarsest level there is).
size_t level_for_faces(const ProgressiveMesh& pm, size_t max_faces);

// The smallest level whose error is <= max_error (see above). max_error < 0 gives n (no
// level is that good; the full mesh is the best there is); NaN throws Error(kInvalidInput).
size_t level_for_error(const ProgressiveMesh& pm, double max_error);

// Level `level` as a Mesh (PmCursor::extract); throws Error(kInvalidInput) when level > n or
// when the PM is corrupt.
Mesh level_of_detail(const ProgressiveMesh& pm, size_t level);

}  // namespace parapm
