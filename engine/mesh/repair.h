// Validation and repair: turns what a reader produced into a mesh the engine can simplify,
// and records what it changed so that a Progressive Mesh can still give back the input.
//
// Rules (each either an error or a counted repair; docs/ARCHITECTURE.md lists them):
//  - NaN or infinite coordinates, NaN attributes: error naming the vertex.
//  - face corners out of range: error (readers already check; repeated here for meshes
//    that arrive by other paths, such as the network).
//  - degenerate faces (a vertex repeated): removed, counted.
//  - duplicate faces (same vertices, same orientation, any rotation): all but the first
//    removed, counted. Faces with the same vertices but opposite orientation are kept.
//  - unreferenced vertices: removed and counted, unless keep_unreferenced is set (then they
//    stay as isolated vertices, which the simplifier never touches).
//  - non-manifold edges (more than two faces, or two faces using the edge in the same
//    direction) and non-manifold vertices (several fans): the mesh is cut along such edges
//    and each extra fan of a vertex gets a copy of the vertex, so the engine sees a
//    manifold; `copies` records which vertex each copy duplicates, so the full-resolution
//    PM gives back the input's vertices once copies are merged.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

struct RepairOptions {
  bool keep_unreferenced = false;
};

struct RepairReport {
  uint64_t degenerate_faces_removed = 0;
  uint64_t duplicate_faces_removed = 0;
  uint64_t unreferenced_vertices_removed = 0;
  uint64_t nonmanifold_edges = 0;      // edges the mesh was cut along
  uint64_t nonmanifold_vertices = 0;   // vertices that received at least one copy
  uint64_t vertex_copies_added = 0;
  uint64_t zero_area_faces = 0;        // distinct vertices but zero area: kept, counted
  bool changed() const {
    return degenerate_faces_removed || duplicate_faces_removed ||
           unreferenced_vertices_removed || vertex_copies_added;
  }
};

struct RepairedMesh {
  Mesh mesh;  // manifold, no degenerate or duplicate faces
  // For each vertex of `mesh`: the vertex of the input it came from. Copies made to split a
  // non-manifold vertex map to the same input vertex as the original.
  std::vector<VertexId> input_vertex;
  // For each face of `mesh`: its index among the input's faces (after fan triangulation).
  std::vector<FaceId> input_face;
  RepairReport report;
};

RepairedMesh repair_mesh(const Mesh& input, const RepairOptions& options = {});

}  // namespace parapm
