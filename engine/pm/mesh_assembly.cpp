// assemble_mesh (mesh_assembly.h): one output wedge per distinct (corner vertex, PM wedge)
// pair. Almost every PM wedge is used by a single vertex, so each wedge remembers the first
// vertex that uses it and only the exceptions go to a sorted side list: linear time in the
// number of corners plus a sort of the exceptions.
#include "pm/mesh_assembly.h"

#include <algorithm>
#include <string>

#include "util/error.h"

namespace parapm {

Mesh assemble_mesh(std::vector<Vec3> positions, std::vector<Triangle> faces,
                   const std::vector<std::array<WedgeId, 3>>& face_wedges,
                   const std::vector<float>& wedge_values, const AttributeLayout& layout,
                   bool positions_are_float, std::vector<WedgeId>* wedge_source) {
  Mesh mesh;
  mesh.positions = std::move(positions);
  mesh.faces = std::move(faces);
  mesh.layout = layout;
  mesh.positions_are_float = positions_are_float;
  if (wedge_source) wedge_source->clear();
  if (!layout.any()) return mesh;

  const size_t fpw = size_t(layout.floats_per_wedge());
  const size_t pm_wedges = wedge_values.size() / fpw;
  if (face_wedges.size() != mesh.faces.size())
    throw_invalid("assemble_mesh: corner wedges missing for some faces");

  // Pass 1: the first vertex of each PM wedge, and the (wedge, vertex) pairs beyond it.
  std::vector<VertexId> first_vertex(pm_wedges, kNoId);
  std::vector<uint64_t> extra;  // wedge << 32 | vertex
  for (FaceId f = 0; f < mesh.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const WedgeId w = face_wedges[f][k];
      const VertexId v = mesh.faces[f][k];
      if (w >= pm_wedges)
        throw_invalid("face " + std::to_string(f) + " names wedge " + std::to_string(w) + " of " +
                      std::to_string(pm_wedges));
      if (first_vertex[w] == kNoId)
        first_vertex[w] = v;
      else if (first_vertex[w] != v)
        extra.push_back(uint64_t(w) << 32 | v);
    }
  }
  std::sort(extra.begin(), extra.end());
  extra.erase(std::unique(extra.begin(), extra.end()), extra.end());

  // Pass 2: number the output wedges and copy their values.
  std::vector<WedgeId> id_of(pm_wedges, kNoId);
  std::vector<WedgeId> extra_id(extra.size());
  size_t next_extra = 0;
  auto add_wedge = [&](WedgeId w, VertexId v) {
    const WedgeId id = WedgeId(mesh.wedge_vertex.size());
    mesh.wedge_vertex.push_back(v);
    mesh.wedge_values.insert(mesh.wedge_values.end(), wedge_values.begin() + w * fpw,
                             wedge_values.begin() + (w + 1) * fpw);
    if (wedge_source) wedge_source->push_back(w);
    return id;
  };
  for (WedgeId w = 0; w < pm_wedges; ++w) {
    if (first_vertex[w] == kNoId) continue;
    id_of[w] = add_wedge(w, first_vertex[w]);
    for (; next_extra < extra.size() && (extra[next_extra] >> 32) == w; ++next_extra)
      extra_id[next_extra] = add_wedge(w, VertexId(extra[next_extra]));
  }

  // Pass 3: the corners.
  mesh.face_wedges.resize(mesh.faces.size());
  for (FaceId f = 0; f < mesh.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const WedgeId w = face_wedges[f][k];
      const VertexId v = mesh.faces[f][k];
      if (first_vertex[w] == v) {
        mesh.face_wedges[f][k] = id_of[w];
      } else {
        const auto it = std::lower_bound(extra.begin(), extra.end(), uint64_t(w) << 32 | v);
        mesh.face_wedges[f][k] = extra_id[size_t(it - extra.begin())];
      }
    }
  }
  return mesh;
}

}  // namespace parapm
