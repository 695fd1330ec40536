// restore_input (pm_restore.h): full resolution, copies merged, input order restored.
#include "pm/pm_restore.h"

#include <algorithm>
#include <numeric>

#include "pm/mesh_assembly.h"
#include "pm/pm_cursor.h"

namespace parapm {

Mesh restore_input(const ProgressiveMesh& pm) {
  validate_pm(pm);
  PmCursor cursor(pm);
  cursor.go_to_level(pm.splits.size());
  const size_t n = cursor.vertex_count();

  // 1. Copies point to their original (validate_pm: originals are never copies).
  std::vector<VertexId> target(n);
  std::iota(target.begin(), target.end(), VertexId(0));
  for (const auto& [copy, original] : pm.vertex_copies) target[copy] = original;
  std::vector<VertexId> kept;
  kept.reserve(n - pm.vertex_copies.size());
  for (VertexId v = 0; v < n; ++v)
    if (target[v] == v) kept.push_back(v);

  // 2. Input order (validate_pm: injective on the kept vertices and on the faces).
  if (!pm.input_vertex_order.empty())
    std::sort(kept.begin(), kept.end(), [&](VertexId a, VertexId b) {
      return pm.input_vertex_order[a] < pm.input_vertex_order[b];
    });
  std::vector<VertexId> new_id(n, kNoId);
  std::vector<Vec3> positions(kept.size());
  for (VertexId i = 0; i < kept.size(); ++i) {
    new_id[kept[i]] = i;
    positions[i] = cursor.positions()[kept[i]];
  }
  for (const auto& [copy, original] : pm.vertex_copies) new_id[copy] = new_id[original];

  const size_t face_count = cursor.face_count();
  std::vector<FaceId> order(face_count);
  std::iota(order.begin(), order.end(), FaceId(0));
  if (!pm.input_face_order.empty())
    std::sort(order.begin(), order.end(),
              [&](FaceId a, FaceId b) { return pm.input_face_order[a] < pm.input_face_order[b]; });
  const bool attributes = pm.base.layout.any();
  std::vector<Triangle> faces(face_count);
  std::vector<std::array<WedgeId, 3>> face_wedges(attributes ? face_count : 0);
  for (FaceId i = 0; i < face_count; ++i) {
    const Triangle& t = cursor.faces()[order[i]];
    faces[i] = {new_id[t[0]], new_id[t[1]], new_id[t[2]]};
    if (attributes) face_wedges[i] = cursor.face_wedges()[order[i]];
  }
  return assemble_mesh(std::move(positions), std::move(faces), face_wedges, cursor.wedge_values(),
                       pm.base.layout, pm.base.positions_are_float);
}

}  // namespace parapm
