#include "parallel/border_band.h"

#include <vector>

#include "pm/levels.h"
#include "pm/pm_cursor.h"

namespace parapm {

// PM ids are stable across levels: vertex i and face f of a level are vertex i and face f of
// every finer level (progressive_mesh.h), so a face is an input face exactly when its corners
// and their positions are those it has at full resolution.
LevelBand original_faces_at(const ProgressiveMesh& pm, size_t max_faces) {
  LevelBand band;
  band.level = level_for_faces(pm, max_faces);
  PmCursor cursor(pm);
  cursor.go_to_level(band.level);
  const std::vector<Triangle> faces = cursor.faces();
  const std::vector<Vec3> positions = cursor.positions();
  cursor.go_to_level(cursor.max_level());
  band.faces = faces.size();
  for (FaceId f = 0; f < faces.size(); ++f) {
    if (faces[f] != cursor.faces()[f]) continue;
    bool moved = false;
    for (VertexId v : faces[f]) moved = moved || positions[v] != cursor.positions()[v];
    if (!moved) ++band.original_faces;
  }
  return band;
}

}  // namespace parapm
