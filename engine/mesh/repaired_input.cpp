#include "mesh/repaired_input.h"

#include <algorithm>
#include <numeric>

namespace parapm {

Mesh repaired_input(const RepairedMesh& repaired) {
  const Mesh& mesh = repaired.mesh;
  Mesh out;
  out.layout = mesh.layout;
  out.positions_are_float = mesh.positions_are_float;

  // Input vertices that survived, in input order, numbered compactly.
  std::vector<VertexId> inputs(repaired.input_vertex.begin(), repaired.input_vertex.end());
  std::sort(inputs.begin(), inputs.end());
  inputs.erase(std::unique(inputs.begin(), inputs.end()), inputs.end());
  auto compact = [&](VertexId input) {
    return VertexId(std::lower_bound(inputs.begin(), inputs.end(), input) - inputs.begin());
  };
  out.positions.resize(inputs.size());
  std::vector<VertexId> merged(mesh.vertex_count());
  for (VertexId v = 0; v < mesh.vertex_count(); ++v) {
    merged[v] = compact(repaired.input_vertex[v]);
    out.positions[merged[v]] = mesh.positions[v];
  }

  std::vector<FaceId> order(mesh.face_count());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](FaceId a, FaceId b) { return repaired.input_face[a] < repaired.input_face[b]; });
  out.faces.reserve(order.size());
  for (FaceId f : order) {
    const Triangle& t = mesh.faces[f];
    out.faces.push_back({merged[t[0]], merged[t[1]], merged[t[2]]});
    if (mesh.layout.any()) out.face_wedges.push_back(mesh.face_wedges[f]);
  }
  if (mesh.layout.any()) {
    out.wedge_values = mesh.wedge_values;
    out.wedge_vertex.resize(mesh.wedge_count());
    for (WedgeId w = 0; w < mesh.wedge_count(); ++w)
      out.wedge_vertex[w] = merged[mesh.wedge_vertex[w]];
  }
  return out;
}

}  // namespace parapm
