// The measure of METHOD.md section 4, weakness 3: the 1999 build left the faces along the
// subsets' borders at full resolution at every level. Counts the faces of a level of detail
// that are faces of the input, unchanged: same corners, and no corner moved.
#pragma once

#include <cstddef>

#include "pm/progressive_mesh.h"

namespace parapm {

struct LevelBand {
  size_t level = 0;
  size_t faces = 0;           // of the level
  size_t original_faces = 0;  // of those, faces of the full-resolution mesh, untouched
  double fraction() const { return faces ? double(original_faces) / double(faces) : 0.0; }
};

// At the largest level with at most max_faces faces (levels.h). Throws Error(kInvalidInput)
// for a corrupt PM.
LevelBand original_faces_at(const ProgressiveMesh& pm, size_t max_faces);

}  // namespace parapm
