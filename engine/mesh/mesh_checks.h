// Invariant checks on a Mesh, in the spirit of Hoppe's `ok()` (libHh): the tests call them on
// what repair_mesh() returns, and other parts of the engine call them where they rely on the
// invariant (the simplifier builds a halfedge structure, which needs an oriented manifold).
//
// They are written independently of the repair step (a plain sort of the edges, a
// union-find over corners), so that a bug in one is not silently shared by the other.
// O(F log F) time, about 40 bytes per face of scratch memory. Thread-safe: no shared state.
#pragma once

#include <cstdint>
#include <string>

#include "mesh/mesh.h"

namespace parapm {

// Counts that describe a mesh's topology. Degenerate faces (a vertex repeated) are counted
// and then left out of everything else: their "edges" are not edges of a surface.
struct TopologyStats {
  uint64_t vertices = 0;
  uint64_t isolated_vertices = 0;  // referenced by no (non-degenerate) face
  uint64_t faces = 0;
  uint64_t degenerate_faces = 0;  // a vertex index repeated
  uint64_t edges = 0;             // undirected edges of the non-degenerate faces
  uint64_t boundary_edges = 0;    // exactly one face
  // Edges with three or more faces, or with two faces that use the edge in the same
  // direction (inconsistent orientation, which includes exact duplicate faces).
  uint64_t nonmanifold_edges = 0;
  uint64_t inconsistent_edges = 0;  // of those, exactly two faces in the same direction
  // Vertices whose faces, connected through the manifold edges around the vertex, form more
  // than one fan (a bowtie, or the faces around a non-manifold edge).
  uint64_t nonmanifold_vertices = 0;
  uint64_t components = 0;  // of the faces, two faces being connected when they share a vertex
  // Referenced vertices - edges + faces (isolated vertices and degenerate faces left out);
  // 2 - 2 * genus per closed connected orientable surface.
  int64_t euler_characteristic = 0;
};

// Throws Error(kInvalidInput) when a face corner is out of range.
TopologyStats topology_stats(const Mesh& mesh);

// True when the faces form an oriented 2-manifold, possibly with boundary: corners in range,
// no degenerate face, every edge has one face or two faces that use it in opposite
// directions, and the faces of every vertex form a single fan (a disk, or a half-disk on the
// boundary), which is what a halfedge structure can represent. Isolated vertices are
// allowed. Otherwise returns false and, when `why` is given, describes the first problem
// found (e.g. "edge (3, 7) has 3 faces: 2, 5, 9").
bool is_oriented_manifold(const Mesh& mesh, std::string* why = nullptr);

// True when the wedge arrays agree with the layout and the faces: sizes, ids in range, and
// the wedge of each face corner belongs to that corner's vertex. Otherwise false with the
// first problem in `why`. Attribute values are not looked at.
bool wedges_are_consistent(const Mesh& mesh, std::string* why = nullptr);

}  // namespace parapm
