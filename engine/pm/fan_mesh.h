// FanMesh: a triangle mesh with vertex -> face adjacency, and the vertex split applied to it
// (Hoppe, "Progressive Meshes", SIGGRAPH 96, section 3.1; the fan rule of progressive_mesh.h).
// PmCursor (sequential levels, with undo) and selective refinement (splits applied out of
// the PM's order) share it, so that both find the faces that move from vs to vt the same way.
//
// Cost: finding a fan and splitting take time proportional to the valence of vs (a vertex of
// valence d above kSortedFanThreshold is indexed by sorting, O(d log d)). Memory: positions
// (24 B/vertex), faces (12 B/face), corner wedges when present (12 B/face), one 64-byte face
// list per vertex (face_lists.h).
//
// The mesh is not assumed manifold: a corrupt PM can make it anything. Every walk is bounded
// by the valence of vs and a configuration that does not match the rule is reported, never
// looped on.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "pm/face_lists.h"
#include "pm/progressive_mesh.h"

namespace parapm {

class FanMesh {
 public:
  // Starts as a copy of `base`; `attributes` keeps its corner wedges per face. Further vertex
  // ids are made valid with ensure_vertex() before a split creates them.
  FanMesh(const Mesh& base, bool attributes);

  // Finds the faces of vs that move to vt when `s` is applied (its vs, vl, vr; the caller has
  // checked that they name existing vertices). Returns an empty string and fills `fan` when
  // the configuration matches the rule, otherwise says what is wrong (the mesh is unchanged).
  std::string find_fan(const VertexSplit& s, std::vector<FaceId>& fan);

  // Applies `s` with the fan from find_fan(): vertex `vt` (which must have no faces) receives
  // the fan, faces fl then fr are appended with the split's corner wedges. Positions are the
  // caller's business (set_position).
  void split(const VertexSplit& s, VertexId vt, std::span<const FaceId> fan);

  // Exact inverse of the last split(s, vt, ...): vt's faces other than fl and fr (the last
  // faces) go back to vs, fl and fr are removed. Splits are undone last-in first-out.
  void unsplit(const VertexSplit& s, VertexId vt);

  // Grows the vertex arrays so that `v` is a valid id (it starts with no faces).
  void ensure_vertex(VertexId v);
  // Hints for a caller that knows which splits come next: the memory a split of v will read
  // (its face list and position; then its faces, once the list is in cache). Applying splits
  // is bound by cache misses at random places, and overlapping them pays.
  void prefetch_vertex(VertexId v) const;
  void prefetch_faces_of(VertexId v) const;
  // Reserves room for this many vertices and faces (avoids regrowing big arrays).
  void reserve(size_t vertices, size_t faces);
  void pop_vertex();  // removes the last vertex id (which must have no faces)

  size_t vertex_count() const { return positions_.size(); }
  size_t face_count() const { return faces_.size(); }
  const std::vector<Vec3>& positions() const { return positions_; }
  void set_position(VertexId v, const Vec3& p) { positions_[v] = p; }
  const std::vector<Triangle>& faces() const { return faces_; }
  const std::vector<std::array<WedgeId, 3>>& face_wedges() const { return face_wedges_; }
  // The faces incident to v, in no particular order.
  std::span<const FaceId> faces_of(VertexId v) const { return vertex_faces_.of(v); }

  static constexpr size_t kSortedFanThreshold = 24;

 private:
  // A face of vs seen from vs: (vs, a, b) counter-clockwise.
  struct Corner {
    VertexId a;
    VertexId b;
    FaceId face;
  };
  static constexpr uint32_t kNone = kNoId;
  uint32_t find_a(VertexId x) const;  // index in ring_ of the face holding vs->x, or kNone
  uint32_t find_b(VertexId x) const;  // index in ring_ of the face holding x->vs, or kNone

  std::vector<Vec3> positions_;
  std::vector<Triangle> faces_;
  std::vector<std::array<WedgeId, 3>> face_wedges_;
  FaceLists vertex_faces_;
  bool attributes_;

  // Scratch for find_fan, kept to avoid allocations per split.
  std::vector<Corner> ring_;
  std::vector<uint32_t> by_a_, by_b_;  // ring_ indices sorted by a, by b (large fans only)
  std::vector<uint8_t> visited_;
  std::vector<FaceId> scratch_;
};

}  // namespace parapm
