// Geomorph construction and evaluation (geomorph.h). One cursor walks up to the coarse level
// (positions and wedge values recorded there), then on to the fine level; ancestors come
// from the split records alone, in one pass in creation order.
#include "pm/geomorph.h"

#include <cmath>
#include <string>

#include "pm/mesh_assembly.h"
#include "pm/pm_cursor.h"
#include "util/error.h"

namespace parapm {

Geomorph make_geomorph(const ProgressiveMesh& pm, size_t coarse_level, size_t fine_level) {
  if (coarse_level > fine_level || fine_level > pm.splits.size())
    throw_invalid("geomorph levels " + std::to_string(coarse_level) + " -> " +
                  std::to_string(fine_level) + " out of order or range (the PM has " +
                  std::to_string(pm.splits.size()) + " splits)");
  Geomorph g;
  g.coarse_level = coarse_level;
  g.fine_level = fine_level;

  PmCursor cursor(pm);
  cursor.go_to_level(coarse_level);
  const std::vector<Vec3> coarse_position = cursor.positions();
  const std::vector<float> coarse_values = cursor.wedge_values();
  const size_t coarse_wedges = cursor.wedge_count();
  cursor.go_to_level(fine_level);

  // A split's vs is older than its vt, so ancestors are settled in creation order.
  const size_t n_coarse = coarse_position.size();
  const size_t n_fine = cursor.vertex_count();
  g.ancestor.resize(n_fine);
  for (VertexId v = 0; v < n_fine; ++v)
    g.ancestor[v] = v < n_coarse ? v : g.ancestor[pm.splits[v - pm.base.vertex_count()].vs];
  g.coarse_positions.resize(n_fine);
  for (VertexId v = 0; v < n_fine; ++v) g.coarse_positions[v] = coarse_position[g.ancestor[v]];

  std::vector<WedgeId> source;
  g.fine =
      assemble_mesh(cursor.positions(), cursor.faces(), cursor.face_wedges(), cursor.wedge_values(),
                    pm.base.layout, pm.base.positions_are_float, &source);
  const size_t fpw = size_t(pm.base.layout.floats_per_wedge());
  g.coarse_wedge_values = g.fine.wedge_values;
  for (WedgeId w = 0; w < source.size(); ++w)
    if (source[w] < coarse_wedges)
      std::copy(coarse_values.begin() + source[w] * fpw,
                coarse_values.begin() + (source[w] + 1) * fpw,
                g.coarse_wedge_values.begin() + w * fpw);
  return g;
}

Mesh Geomorph::at(double alpha) const {
  if (!(alpha >= 0 && alpha <= 1))
    throw_invalid("geomorph blend " + std::to_string(alpha) + " is outside [0, 1]");
  Mesh mesh = fine;
  if (alpha == 1) return mesh;
  if (alpha == 0) {
    mesh.positions = coarse_positions;
    mesh.wedge_values = coarse_wedge_values;
    return mesh;
  }
  const double beta = 1 - alpha;
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    for (int k = 0; k < 3; ++k)
      mesh.positions[v][k] = beta * coarse_positions[v][k] + alpha * fine.positions[v][k];
  for (size_t i = 0; i < mesh.wedge_values.size(); ++i)
    mesh.wedge_values[i] =
        float(beta * double(coarse_wedge_values[i]) + alpha * double(fine.wedge_values[i]));
  mesh.positions_are_float = false;
  return mesh;
}

}  // namespace parapm
