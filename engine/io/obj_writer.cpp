// OBJ writer: positions as "v x y z" in shortest round-trip decimal (they read back bit for
// bit), colours on the v lines ("v x y z r g b", plus alpha when some alpha is not 1) taken from
// each vertex's first wedge, one vt and/or vn line per wedge, faces as v, v/vt, v//vn or
// v/vt/vn with 1-based indices (vt and vn indices are wedge numbers).
#include <string>
#include <vector>

#include "io/formats.h"
#include "io/number_format.h"

namespace parapm::io {
namespace {

void append_index(std::string& out, uint64_t one_based) { append_number(out, one_based); }

}  // namespace

std::string write_obj(const Mesh& mesh) {
  const AttributeLayout& layout = mesh.layout;
  const bool has_wedges = layout.any();
  const size_t nw = has_wedges ? mesh.wedge_count() : 0;
  std::string out;
  out.reserve(mesh.positions.size() * 40 + nw * 40 + mesh.faces.size() * 30 + 128);
  out += "# written by ParaPM: " + std::to_string(mesh.positions.size()) + " vertices, " +
         std::to_string(mesh.faces.size()) + " triangles\n";

  // Colours are per vertex in OBJ: each vertex takes its first wedge's colour (opaque white
  // when it has no wedge; such a vertex is not used by any face).
  std::vector<WedgeId> first_wedge;
  bool write_alpha = false;
  if (layout.colors) {
    first_wedge.assign(mesh.positions.size(), kNoId);
    for (WedgeId w = WedgeId(nw); w-- > 0;) first_wedge[mesh.wedge_vertex[w]] = w;
    for (WedgeId w = 0; w < nw; ++w)
      if (mesh.wedge(w)[layout.color_offset() + 3] != 1.0f) write_alpha = true;
  }
  static constexpr float kWhite[4] = {1, 1, 1, 1};
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    out += 'v';
    for (double c : mesh.positions[v]) {
      out += ' ';
      append_number(out, c);
    }
    if (layout.colors) {
      const float* rgba =
          first_wedge[v] == kNoId ? kWhite : mesh.wedge(first_wedge[v]) + layout.color_offset();
      for (int k = 0; k < (write_alpha ? 4 : 3); ++k) {
        out += ' ';
        append_number(out, rgba[k]);
      }
    }
    out += '\n';
  }
  if (layout.texcoords)
    for (WedgeId w = 0; w < nw; ++w) {
      const float* uv = mesh.wedge(w) + layout.texcoord_offset();
      out += "vt ";
      append_number(out, uv[0]);
      out += ' ';
      append_number(out, uv[1]);
      out += '\n';
    }
  if (layout.normals)
    for (WedgeId w = 0; w < nw; ++w) {
      const float* n = mesh.wedge(w) + layout.normal_offset();
      out += "vn ";
      append_number(out, n[0]);
      out += ' ';
      append_number(out, n[1]);
      out += ' ';
      append_number(out, n[2]);
      out += '\n';
    }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_index(out, uint64_t(mesh.faces[f][k]) + 1);
      if (!layout.texcoords && !layout.normals) continue;
      const uint64_t w = uint64_t(mesh.face_wedges[f][k]) + 1;
      out += '/';
      if (layout.texcoords) append_index(out, w);
      if (layout.normals) {
        out += '/';
        append_index(out, w);
      }
    }
    out += '\n';
  }
  return out;
}

}  // namespace parapm::io
