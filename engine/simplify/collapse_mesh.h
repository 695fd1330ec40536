// The working mesh of the simplifier: an indexed triangle mesh with vertex -> face
// adjacency, on which edge collapses are performed in place (Hoppe 96, section 3).
//
// It is deliberately not a halfedge structure: the collapse engine needs only "the faces
// around a vertex" and "the face holding a directed edge", both answered by scanning the
// vertex's face list (valence ~6), and a flat list keeps a collapse cheap. Faces keep their
// ids for the whole run; a collapsed face is marked dead.
//
// Preconditions: the mesh is an oriented 2-manifold with boundary (repair_mesh output).
// Memory: about 110 bytes per vertex (a 64-byte face list, face_lists.h) plus 32 bytes per
// face beyond the input mesh.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/mesh.h"
#include "pm/face_lists.h"
#include "util/chunked_loops.h"

namespace parapm {

struct EdgeFaces {
  FaceId left = kNoId;   // the face holding the directed edge a->b: (a, b, left_apex)
  FaceId right = kNoId;  // the face holding b->a: (b, a, right_apex)
  VertexId left_apex = kNoId;
  VertexId right_apex = kNoId;
};

class CollapseMesh {
 public:
  explicit CollapseMesh(const Mesh& mesh);
  // The same mesh, its adjacency built in `loops`' chunks side by side.
  CollapseMesh(const Mesh& mesh, ChunkedLoops& loops);

  size_t vertex_capacity() const { return positions_.size(); }
  size_t face_capacity() const { return faces_.size(); }
  size_t live_faces() const { return live_faces_; }
  size_t live_vertices() const { return live_vertices_; }

  bool vertex_alive(VertexId v) const { return vertex_alive_[v]; }  // has faces
  void prefetch_vertex_alive(VertexId v) const { __builtin_prefetch(&vertex_alive_[v]); }
  // Starts loading v's position and face list.
  void prefetch_vertex(VertexId v) const {
    __builtin_prefetch(&positions_[v]);
    faces_of_.prefetch(v);
  }
  bool face_alive(FaceId f) const { return face_alive_[f]; }
  const Triangle& face(FaceId f) const { return faces_[f]; }
  const std::array<WedgeId, 3>& corner_wedges(FaceId f) const { return corner_wedges_[f]; }
  bool has_wedges() const { return !corner_wedges_.empty(); }
  // The faces around v, valid until a collapse changes v's star.
  std::span<const FaceId> faces_of(VertexId v) const { return faces_of_.of(v); }
  const Vec3& position(VertexId v) const { return positions_[v]; }
  const std::vector<Vec3>& positions() const { return positions_; }  // removed ones included
  bool is_boundary(VertexId v) const { return boundary_[v]; }
  // Changes whenever a collapse changes v's star (its faces, or where their corners are): sums
  // over a star kept with it are current while it reads the same.
  uint32_t star_version(VertexId v) const { return star_version_[v]; }
  // A number no other mesh shares (a copy or a new build draws its own): says which mesh a
  // kept star sum is of.
  uint64_t identity() const { return identity_.value; }

  EdgeFaces edge_faces(VertexId a, VertexId b) const;
  // For every corner slot 3 f + k of a live face f, the face across its edge t[k] -> t[k + 1]
  // (the one holding t[k + 1] -> t[k]; kNoId on a boundary), dead faces' slots kNoId: what
  // edge_faces(t[k + 1], t[k]).left gives for each, in one pass over the vertices' fans (each
  // face read three times, not six times per edge: passes over every edge, such as a first
  // queue or the sharp edges' search, used to spend most of their time in those lookups).
  std::vector<FaceId> twin_faces() const;
  std::vector<FaceId> twin_faces(ChunkedLoops& loops) const;  // in loops' chunks, the same
  // The distinct vertices sharing a face with v, in no particular order.
  void neighbors(VertexId v, std::vector<VertexId>& out) const;
  // Calls visit(n) once for every vertex n adjacent to both a and b.
  template <typename Visit>
  void for_each_common_neighbor(VertexId a, VertexId b, Visit visit) const {
    const uint32_t seen = next_stamp();
    for (FaceId f : faces_of(a))
      for (VertexId n : faces_[f]) mark_[n] = seen;
    const uint32_t done = next_stamp();
    // (tested together, not one after the other: b is a corner of every face, in any of the
    // three places, and the common neighbours are few)
    for (FaceId f : faces_of(b))
      for (VertexId n : faces_[f])
        if ((n != a) & (n != b) & (mark_[n] == seen)) {
          mark_[n] = done;
          visit(n);
        }
  }

  // Merges vt into vs, moves vs to `position`, removes the faces on the edge: `edge` must be
  // edge_faces(vs, vt) of the present mesh (the caller computed it to check legality).
  // Collapses of disjoint regions may run concurrently (parallel/collapse_merge.h) if each
  // counts the live faces and vertices it removes in its own `removed` instead of the mesh's
  // counts, added afterwards with count_removed.
  struct RemovedCounts {
    size_t faces = 0, vertices = 0;
  };
  // The star versions it changes are those of vs, vt, the apexes and vs's neighbours: all
  // owned by the collapse's subset under the subset rule, so concurrent collapses share none.
  void collapse(VertexId vs, VertexId vt, const Vec3& position, const EdgeFaces& edge,
                RemovedCounts* removed = nullptr);
  void count_removed(const RemovedCounts& removed);
  // Lists v's faces in the order given, which must be the faces v has: the order another mesh
  // lists them in, for a copy of part of it (parallel/live_pass.h) whose run follows fan order
  // where that mesh's run does (the order the edges around a collapse are queued in).
  void order_faces_of(VertexId v, std::span<const FaceId> faces);

 private:
  void build(const Mesh& mesh, ChunkedLoops& loops);
  void remove_face_from(VertexId v, FaceId f);
  uint32_t next_stamp() const;
  // Over v's faces, the sum of the corners after v less the sum of the corners before it (ids,
  // modulo 2^64): not 0 exactly when v is on the boundary (the reason at its definition).
  uint64_t fan_imbalance(VertexId v) const;

  std::vector<Vec3> positions_;
  std::vector<Triangle> faces_;
  std::vector<std::array<WedgeId, 3>> corner_wedges_;
  std::vector<uint8_t> face_alive_;
  std::vector<uint8_t> vertex_alive_;  // a byte per vertex: the queue checks it on every pop
  FaceLists faces_of_;
  std::vector<uint8_t> boundary_;
  // Per vertex, fan_imbalance() as collapses change it (a few corners each), so that the
  // apexes' boundary status needs no pass over their faces: boundary_[v] is imbalance_[v] != 0
  // for vs and the apexes after each collapse.
  std::vector<uint64_t> imbalance_;
  std::vector<uint32_t> star_version_;
  // Drawn anew by every construction, copy and assignment.
  struct Identity {
    uint64_t value = next();
    Identity() = default;
    Identity(const Identity&) : value(next()) {}
    Identity& operator=(const Identity&) {
      value = next();
      return *this;
    }
    static uint64_t next();
  } identity_;
  size_t live_faces_ = 0;
  size_t live_vertices_ = 0;
  // Scratch marks for neighbourhood queries (instead of sorting): a vertex is marked when
  // mark_[v] equals the current stamp. Queries are const but not thread-safe.
  mutable std::vector<uint32_t> mark_;
  mutable uint32_t stamp_ = 0;
};

// Numbers the connected components of the live part of `mesh`: component[v] is the index of
// v's component (in order of their smallest vertex), kNoId for a removed vertex. Returns the
// number of components.
uint32_t connected_components(const CollapseMesh& mesh, std::vector<uint32_t>& component);

// Index of vertex v among the corners of face t (0, 1, 2; the first where it repeats), or -1.
// Without a branch: which corner a face's vertex is follows no pattern a predictor learns.
inline int corner_of(const Triangle& t, VertexId v) {
  int corner = t[2] == v ? 2 : -1;
  corner = t[1] == v ? 1 : corner;
  return t[0] == v ? 0 : corner;
}

}  // namespace parapm
