#include "mesh/outgoing_halfedges.h"

namespace parapm {

OutgoingHalfedges outgoing_halfedges(const std::vector<Triangle>& faces, size_t vertex_count) {
  OutgoingHalfedges out;
  out.begin.assign(vertex_count + 1, 0);
  for (const Triangle& t : faces)
    for (VertexId v : t) ++out.begin[v + 1];
  for (size_t v = 0; v < vertex_count; ++v) out.begin[v + 1] += out.begin[v];
  out.halfedges.resize(out.begin.back());
  std::vector<uint32_t> next(out.begin.begin(), out.begin.end() - 1);
  for (FaceId f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) out.halfedges[next[faces[f][k]]++] = {faces[f][(k + 1) % 3], f};
  return out;
}

}  // namespace parapm
