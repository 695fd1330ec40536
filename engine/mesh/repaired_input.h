// The input "after the documented repairs": what a lossless Progressive Mesh must give back
// at full resolution. It is the repaired mesh with the copies that made it manifold merged
// back into their input vertex, vertices and faces in the input's order (removed ones
// skipped, the rest renumbered compactly).
#pragma once

#include "mesh/repair.h"

namespace parapm {

Mesh repaired_input(const RepairedMesh& repaired);

}  // namespace parapm
