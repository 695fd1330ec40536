// OpenMesh adapters (CMake: find_package(ParaPM) and link ParaPM::openmesh, which brings
// OpenMesh's OpenMeshCore): an OpenMesh triangle mesh to ParaPM's Mesh and back, and OpenMesh's
// readers as an input path for the formats ParaPM does not read (.om).
//
//   #include <parapm/engine.h>
//   #include <parapm/openmesh.h>
//
//   parapm::openmesh::TriMesh om;   // or any OpenMesh::TriMesh_ArrayKernelT<Traits>
//   OpenMesh::IO::read_mesh(om, "part.om");
//   const parapm::ProgressiveMesh pm = parapm::build_progressive_mesh(
//       parapm::repair_mesh(parapm::openmesh::from_openmesh(om)), options);
//   const auto level = parapm::openmesh::to_openmesh<parapm::openmesh::TriMesh>(
//       parapm::level_of_detail(pm, parapm::level_for_faces(pm, 5000)));
//
// Attributes: ParaPM keeps one set per face corner (a wedge); OpenMesh per vertex or per
// halfedge (a halfedge's value is its to-vertex's in its face). from_openmesh takes the
// halfedge normals, texture coordinates and colours where the mesh has them, else the vertex
// ones, and makes a wedge of each distinct (vertex, values) set (per-vertex values: wedge i is
// vertex i). to_openmesh sets both: halfedge values per corner and, per vertex, its first
// corner's (for writers that take vertex attributes only). Colours are RGBA in [0, 1] as
// floats (OpenMesh byte colours are divided by 255).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Utils/color_cast.hh>

#include "mesh/mesh.h"
#include "util/error.h"

namespace parapm::openmesh {

// The mesh type of read_openmesh: double positions (ParaPM's), float normals, RGBA float
// colours and 2D texture coordinates, per vertex and per halfedge.
struct Traits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3f;
  using Color = OpenMesh::Vec4f;
  using TexCoord2D = OpenMesh::Vec2f;
};
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<Traits>;

// Reads `path` with OpenMesh's readers (any format OpenMesh reads: .om, .off, .obj, .ply, .stl)
// with the attributes the file has, then checks it as ParaPM's readers do (finite positions,
// at least one face). Throws Error(kInvalidInput) when OpenMesh cannot read it. OpenMesh keeps
// no non-manifold face (it says so on stderr and drops it): for such files ParaPM's own
// readers, which keep and repair them, are the better path.
Mesh read_openmesh(const std::string& path);

namespace detail {

template <class Color>
std::array<float, 4> rgba(const Color& c) {
  const OpenMesh::Vec4f f = OpenMesh::color_cast<OpenMesh::Vec4f>(c);
  return {f[0], f[1], f[2], f[3]};
}

}  // namespace detail

// ParaPM's mesh of an OpenMesh triangle mesh (its vertices and faces in OpenMesh's order).
// Throws Error(kInvalidInput) for a mesh with deleted elements (call garbage_collection()
// first) or a face that is not a triangle.
template <class M>
Mesh from_openmesh(const M& om) {
  if (om.has_vertex_status() || om.has_face_status())
    for (auto f : om.faces())
      if (om.status(f).deleted())
        throw_invalid("from_openmesh: deleted faces (garbage_collection() first)");
  Mesh mesh;
  mesh.positions.reserve(om.n_vertices());
  for (auto v : om.vertices()) {
    const auto p = om.point(v);
    mesh.positions.push_back({double(p[0]), double(p[1]), double(p[2])});
  }
  mesh.faces.reserve(om.n_faces());
  for (auto f : om.faces()) {
    Triangle t{};
    int k = 0;
    for (auto v : om.fv_range(f)) {
      if (k == 3)
        throw_invalid("from_openmesh: face " + std::to_string(f.idx()) + " is not a triangle");
      t[size_t(k++)] = VertexId(v.idx());
    }
    if (k != 3)
      throw_invalid("from_openmesh: face " + std::to_string(f.idx()) + " is not a triangle");
    mesh.faces.push_back(t);
  }
  mesh.positions_are_float = all_positions_are_float(mesh.positions);

  const bool he_normals = om.has_halfedge_normals(), he_uv = om.has_halfedge_texcoords2D(),
             he_colors = om.has_halfedge_colors();
  AttributeLayout& layout = mesh.layout;
  layout.normals = he_normals || om.has_vertex_normals();
  layout.texcoords = he_uv || om.has_vertex_texcoords2D();
  layout.colors = he_colors || om.has_vertex_colors();
  if (!layout.any()) return mesh;
  const int floats = layout.floats_per_wedge();
  const bool per_corner = he_normals || he_uv || he_colors;
  // One corner's values, from its halfedge (the one pointing to its vertex in its face) or
  // its vertex.
  auto corner_values = [&](auto he, auto v, float* out) {
    if (layout.normals) {
      const auto n = he_normals ? om.normal(he) : om.normal(v);
      for (int k = 0; k < 3; ++k) out[layout.normal_offset() + k] = float(n[k]);
    }
    if (layout.texcoords) {
      const auto t = he_uv ? om.texcoord2D(he) : om.texcoord2D(v);
      for (int k = 0; k < 2; ++k) out[layout.texcoord_offset() + k] = float(t[k]);
    }
    if (layout.colors) {
      const std::array<float, 4> c = detail::rgba(he_colors ? om.color(he) : om.color(v));
      for (int k = 0; k < 4; ++k) out[layout.color_offset() + k] = c[size_t(k)];
    }
  };
  std::vector<float> values(static_cast<size_t>(floats));
  if (!per_corner) {  // one wedge per vertex, wedge i of vertex i
    mesh.wedge_values.resize(mesh.positions.size() * size_t(floats));
    for (auto v : om.vertices()) {
      mesh.wedge_vertex.push_back(VertexId(v.idx()));
      corner_values(typename M::HalfedgeHandle(), v,
                    mesh.wedge_values.data() + size_t(v.idx()) * size_t(floats));
    }
    for (const Triangle& t : mesh.faces) mesh.face_wedges.push_back({t[0], t[1], t[2]});
    return mesh;
  }
  std::map<std::pair<VertexId, std::vector<float>>, WedgeId> wedges;
  for (auto f : om.faces()) {
    std::array<WedgeId, 3> corners{};
    for (auto he : om.fh_range(f)) {  // a halfedge's to-vertex is its corner
      const auto v = om.to_vertex_handle(he);
      corner_values(he, v, values.data());
      const auto key = std::make_pair(VertexId(v.idx()), values);
      auto [at, added] = wedges.try_emplace(key, WedgeId(mesh.wedge_vertex.size()));
      if (added) {
        mesh.wedge_vertex.push_back(VertexId(v.idx()));
        mesh.wedge_values.insert(mesh.wedge_values.end(), values.begin(), values.end());
      }
      // fh_range starts at the face's halfedge, whose to-vertex need not be the first corner.
      const Triangle& t = mesh.faces[size_t(f.idx())];
      const size_t corner = t[0] == VertexId(v.idx()) ? 0 : t[1] == VertexId(v.idx()) ? 1 : 2;
      corners[corner] = at->second;
    }
    mesh.face_wedges.push_back(corners);
  }
  // One wedge per vertex after all: numbered as the vertices, as ParaPM's readers number a
  // mesh with per-vertex attributes.
  std::vector<uint32_t> wedges_of(mesh.positions.size(), 0);
  for (VertexId v : mesh.wedge_vertex) ++wedges_of[v];
  if (std::all_of(wedges_of.begin(), wedges_of.end(), [](uint32_t n) { return n == 1; })) {
    std::vector<float> by_vertex(mesh.wedge_values.size());
    for (WedgeId w = 0; w < mesh.wedge_vertex.size(); ++w)
      std::memcpy(by_vertex.data() + size_t(mesh.wedge_vertex[w]) * size_t(floats), mesh.wedge(w),
                  size_t(floats) * sizeof(float));
    for (auto& corners : mesh.face_wedges)
      for (WedgeId& w : corners) w = mesh.wedge_vertex[w];
    mesh.wedge_values = std::move(by_vertex);
    for (VertexId v = 0; v < mesh.wedge_vertex.size(); ++v) mesh.wedge_vertex[v] = v;
  }
  return mesh;
}

// An OpenMesh triangle mesh of ParaPM's mesh (same vertex and face order), with its
// attributes per halfedge and per vertex. Throws Error(kInvalidInput) when OpenMesh refuses a
// face (a non-manifold one: repair_mesh's output never has them).
template <class M>
M to_openmesh(const Mesh& mesh) {
  M om;
  using Point = typename M::Point;
  using Scalar = typename Point::value_type;
  for (const Vec3& p : mesh.positions)
    om.add_vertex(Point(Scalar(p[0]), Scalar(p[1]), Scalar(p[2])));
  const AttributeLayout& layout = mesh.layout;
  if (layout.normals) om.request_halfedge_normals(), om.request_vertex_normals();
  if (layout.texcoords) om.request_halfedge_texcoords2D(), om.request_vertex_texcoords2D();
  if (layout.colors) om.request_halfedge_colors(), om.request_vertex_colors();
  std::vector<bool> vertex_set(mesh.positions.size(), false);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Triangle& t = mesh.faces[f];
    const auto fh = om.add_face(om.vertex_handle(int(t[0])), om.vertex_handle(int(t[1])),
                                om.vertex_handle(int(t[2])));
    if (!fh.is_valid())
      throw_invalid("to_openmesh: OpenMesh refuses face " + std::to_string(f) +
                    " (a non-manifold edge or vertex; repair_mesh the mesh first)");
    if (!layout.any()) continue;
    for (auto he : om.fh_range(fh)) {
      const auto v = om.to_vertex_handle(he);
      const size_t corner = t[0] == VertexId(v.idx()) ? 0 : t[1] == VertexId(v.idx()) ? 1 : 2;
      const float* w = mesh.wedge(mesh.face_wedges[f][corner]);
      const bool first = !vertex_set[size_t(v.idx())];
      vertex_set[size_t(v.idx())] = true;
      if (layout.normals) {
        const typename M::Normal n(w[layout.normal_offset()], w[layout.normal_offset() + 1],
                                   w[layout.normal_offset() + 2]);
        om.set_normal(he, n);
        if (first) om.set_normal(v, n);
      }
      if (layout.texcoords) {
        const typename M::TexCoord2D uv(w[layout.texcoord_offset()],
                                        w[layout.texcoord_offset() + 1]);
        om.set_texcoord2D(he, uv);
        if (first) om.set_texcoord2D(v, uv);
      }
      if (layout.colors) {
        const float* c = w + layout.color_offset();
        const auto color =
            OpenMesh::color_cast<typename M::Color>(OpenMesh::Vec4f(c[0], c[1], c[2], c[3]));
        om.set_color(he, color);
        if (first) om.set_color(v, color);
      }
    }
  }
  return om;
}

}  // namespace parapm::openmesh
