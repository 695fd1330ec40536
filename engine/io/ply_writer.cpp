// PLY writer: binary little endian, or ascii (shortest round-trip decimal).
//   element vertex: x y z as float when the positions are all float32 (positions_are_float and
//     checked), else double; then nx ny nz float, s t float, red green blue alpha uchar
//     (round(c * 255), clamped to [0, 1] first) as the layout has them;
//   element face: list uchar int vertex_indices (uint when indices pass 2^31 - 1).
// PLY attributes are per vertex: the writer emits one PLY vertex per wedge, vertex by vertex
// in vertex order (the wedges of one vertex in wedge order, all with that vertex's position),
// and one PLY vertex with default attributes (zero normal and texcoord, opaque white) for a
// vertex without wedges. A mesh with one wedge per vertex, wedge i on vertex i, keeps its
// numbering.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "io/formats.h"
#include "io/number_format.h"

namespace parapm::io {
namespace {

// Which mesh vertex and which wedge (kNoId: none) each PLY vertex comes from.
struct PlyVertex {
  VertexId vertex;
  WedgeId wedge;
};

std::vector<PlyVertex> ply_vertices(const Mesh& mesh, std::vector<VertexId>* wedge_to_ply) {
  std::vector<PlyVertex> out;
  const size_t nv = mesh.positions.size();
  if (!mesh.layout.any()) {
    out.resize(nv);
    for (size_t v = 0; v < nv; ++v) out[v] = {VertexId(v), kNoId};
    return out;
  }
  // Wedges grouped by vertex, in wedge order (a counting sort).
  const size_t nw = mesh.wedge_count();
  std::vector<uint32_t> start(nv + 1, 0);
  for (VertexId v : mesh.wedge_vertex) ++start[v + 1];
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<WedgeId> by_vertex(nw);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (WedgeId w = 0; w < nw; ++w) by_vertex[fill[mesh.wedge_vertex[w]]++] = w;

  wedge_to_ply->assign(nw, kNoId);
  out.reserve(std::max(nv, nw));
  for (size_t v = 0; v < nv; ++v) {
    if (start[v] == start[v + 1]) out.push_back({VertexId(v), kNoId});
    for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
      (*wedge_to_ply)[by_vertex[i]] = VertexId(out.size());
      out.push_back({VertexId(v), by_vertex[i]});
    }
  }
  return out;
}

uint8_t to_uchar(float c) {
  const float clamped = std::clamp(c, 0.0f, 1.0f);  // NaN stays NaN: map it to 0
  return clamped == clamped ? uint8_t(std::lround(clamped * 255.0f)) : 0;
}

class PlyOut {
 public:
  PlyOut(std::string& out, bool ascii) : out_(out), ascii_(ascii) {}

  template <class T>
  void value(T v) {
    if (ascii_) {
      if (!first_) out_ += ' ';
      first_ = false;
      if constexpr (std::is_same_v<T, uint8_t>)
        append_number(out_, unsigned(v));
      else
        append_number(out_, v);
    } else {
      if constexpr (std::endian::native == std::endian::big && sizeof(T) > 1) {
        auto bits = std::bit_cast<std::conditional_t<sizeof(T) == 4, uint32_t, uint64_t>>(v);
        if constexpr (sizeof(T) == 4) bits = __builtin_bswap32(bits);
        if constexpr (sizeof(T) == 8) bits = __builtin_bswap64(bits);
        out_.append(reinterpret_cast<const char*>(&bits), sizeof bits);
      } else {
        out_.append(reinterpret_cast<const char*>(&v), sizeof v);
      }
    }
  }
  void end_record() {
    if (ascii_) out_ += '\n';
    first_ = true;
  }

 private:
  std::string& out_;
  bool ascii_;
  bool first_ = true;
};

// The PLY vertices the writer emits: one per wedge, one for a vertex without wedges.
uint64_t ply_vertex_count(const Mesh& mesh) {
  if (!mesh.layout.any()) return mesh.positions.size();
  std::vector<uint8_t> has_wedge(mesh.positions.size(), 0);
  for (VertexId v : mesh.wedge_vertex) has_wedge[v] = 1;
  uint64_t count = mesh.wedge_count();
  for (uint8_t h : has_wedge) count += h ? 0 : 1;
  return count;
}

// A binary PLY vertex's bytes: positions, then normals, texcoords (floats) and colours (uchar).
size_t binary_vertex_bytes(const AttributeLayout& layout, bool float_positions) {
  return (float_positions ? 12 : 24) + (layout.normals ? 12 : 0) + (layout.texcoords ? 8 : 0) +
         (layout.colors ? 4 : 0);
}

std::string ply_header(const Mesh& mesh, bool ascii, uint64_t vertices, bool float_positions) {
  const AttributeLayout& layout = mesh.layout;
  std::string out = "ply\n";
  out += ascii ? "format ascii 1.0\n" : "format binary_little_endian 1.0\n";
  out += "comment written by ParaPM\n";
  out += "element vertex " + std::to_string(vertices) + "\n";
  for (const char* axis : {"x", "y", "z"})
    out += std::string("property ") + (float_positions ? "float " : "double ") + axis + "\n";
  if (layout.normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (layout.texcoords) out += "property float s\nproperty float t\n";
  if (layout.colors)
    out += "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n";
  out += "element face " + std::to_string(mesh.faces.size()) + "\n";
  out += vertices > uint64_t(INT32_MAX) ? "property list uchar uint vertex_indices\n"
                                        : "property list uchar int vertex_indices\n";
  out += "end_header\n";
  return out;
}

bool writes_float_positions(const Mesh& mesh) {
  return mesh.positions_are_float && all_positions_are_float(mesh.positions);
}

}  // namespace

uint64_t binary_ply_size(const Mesh& mesh) {
  const bool float_positions = writes_float_positions(mesh);
  const uint64_t vertices = ply_vertex_count(mesh);
  return ply_header(mesh, false, vertices, float_positions).size() +
         vertices * binary_vertex_bytes(mesh.layout, float_positions) +
         mesh.faces.size() * (1 + 3 * 4);
}

std::string write_ply(const Mesh& mesh, bool ascii) {
  const AttributeLayout& layout = mesh.layout;
  std::vector<VertexId> wedge_to_ply;
  const std::vector<PlyVertex> vertices = ply_vertices(mesh, &wedge_to_ply);
  const bool float_positions = writes_float_positions(mesh);
  const bool wide_indices = vertices.size() > uint64_t(INT32_MAX);

  const size_t vertex_bytes = binary_vertex_bytes(layout, float_positions);
  std::string out = ply_header(mesh, ascii, vertices.size(), float_positions);
  out.reserve(out.size() + vertices.size() * (ascii ? 3 * vertex_bytes : vertex_bytes) +
              mesh.faces.size() * (ascii ? 30 : 13));
  PlyOut ply(out, ascii);
  static constexpr float kDefaults[9] = {0, 0, 0, 0, 0, 1, 1, 1, 1};  // normal, uv, rgba
  for (const PlyVertex& pv : vertices) {
    for (double c : mesh.positions[pv.vertex]) {
      if (float_positions)
        ply.value(float(c));
      else
        ply.value(c);
    }
    const float* w = pv.wedge == kNoId ? nullptr : mesh.wedge(pv.wedge);
    if (layout.normals)
      for (int k = 0; k < 3; ++k) ply.value(w ? w[layout.normal_offset() + k] : kDefaults[k]);
    if (layout.texcoords)
      for (int k = 0; k < 2; ++k) ply.value(w ? w[layout.texcoord_offset() + k] : kDefaults[3 + k]);
    if (layout.colors)
      for (int k = 0; k < 4; ++k)
        ply.value(to_uchar(w ? w[layout.color_offset() + k] : kDefaults[5 + k]));
    ply.end_record();
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    ply.value(uint8_t(3));
    for (int k = 0; k < 3; ++k) {
      const uint32_t index = layout.any() ? wedge_to_ply[mesh.face_wedges[f][k]] : mesh.faces[f][k];
      if (wide_indices)
        ply.value(index);
      else
        ply.value(int32_t(index));
    }
    ply.end_record();
  }
  return out;
}

}  // namespace parapm::io
