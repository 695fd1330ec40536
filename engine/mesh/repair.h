// Validation and repair: turns what a reader produced into a mesh the engine can simplify,
// and records what it changed so that a Progressive Mesh can still give back the input.
//
// Rules, applied in this order (each either an error or a counted repair; docs/ARCHITECTURE.md
// lists them):
//  1. Errors, Error(kInvalidInput) naming the vertex, wedge or face: NaN or infinite
//     coordinates or attribute values; face corners out of range (readers already check;
//     repeated here for meshes that arrive by other paths, such as the network); wedge arrays
//     whose sizes disagree with the layout (all empty when the layout has no channel); a face
//     corner whose wedge belongs to another vertex. Meshes with 2^32 - 1 vertices, wedges or
//     more, or more than (2^32 - 2) / 3 faces: Error(kResourceExhausted).
//  2. Degenerate faces (a vertex index repeated): removed, counted. Duplicate faces (same
//     vertices in the same cyclic order, any rotation; wedges are not compared): all but the
//     first removed, counted. Faces with the same vertices but opposite orientation are kept.
//     Faces with distinct vertices but zero area (cross product exactly 0) are kept, counted.
//  3. Unreferenced vertices (including those only removed faces used): removed with their
//     wedges and counted, unless keep_unreferenced is set (then they stay as isolated
//     vertices, which the simplifier never touches). Vertices and wedges keep their relative
//     order. Wedges of kept vertices are kept even when no corner uses them.
//  4. Non-manifold edges and vertices. An undirected edge is manifold when it has one face,
//     or two faces that use it in opposite directions; the mesh is cut along every other edge
//     (three or more faces, or two in the same direction): faces across it are not
//     neighbours, with three exceptions for faces laid back to back on a surface (a face and
//     its reverse, the same vertices in the opposite order), which keep the surface joined and
//     cut off only what lies on it: an edge whose faces are such pairs but for two, in opposite
//     directions, keeps those two joined (a double-sided flap on the surface's edge); an edge
//     of exactly two such pairs keeps each face joined to the face against it that is not its
//     reverse (each side of a double-sided surface joined with itself), unless that makes two
//     faces share a halfedge after the split (a side folding round to the other), where the
//     split is made again with those faces' edges cut; a face whose three edges each hold
//     exactly it, its reverse and one face against it stays joined to those three (its
//     reverse, a back face laid on it, is cut off alone). The faces of each vertex are then
//     grouped into fans, joined through the vertex's manifold edges (and those pairs); the fan
//     holding the vertex's lowest face keeps the vertex, and
//     each further fan gets a copy appended after all vertices (same position; copies ordered
//     by original vertex, then by lowest face), with copies of the wedges its corners use
//     (appended after all wedges). No face is changed other than by naming a copy, and no
//     face is added: the result is an oriented 2-manifold with boundary (a halfedge structure
//     can be built on it), and merging each copy into the vertex of input_vertex gives back
//     the kept faces exactly.
//  5. Unless spatial_order is off: vertices, faces and wedges renumbered for memory locality
//     (spatial_order.h: vertices along a Morton curve, faces by their first vertex, wedges by
//     their vertex). Nothing else changes; input_vertex, input_face and input_wedge follow.
//     Rules 3 and 4's orders are those before this step.
// Deterministic (no hashing, no threads) and O(F log(max valence) + V log V) time.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "util/chunked_loops.h"

namespace parapm {

struct RepairOptions {
  bool keep_unreferenced = false;
  // Rule 5. Off: the output keeps the input's order (rules 3 and 4).
  bool spatial_order = true;
  // Where the passes over faces and edges run in chunks side by side (the same output); null:
  // on the calling thread.
  ChunkedLoops* loops = nullptr;
};

struct RepairReport {
  uint64_t degenerate_faces_removed = 0;
  uint64_t duplicate_faces_removed = 0;
  uint64_t unreferenced_vertices_removed = 0;
  uint64_t nonmanifold_edges = 0;     // edges the mesh was cut along (after step 2)
  uint64_t nonmanifold_vertices = 0;  // vertices that received at least one copy
  uint64_t vertex_copies_added = 0;
  uint64_t zero_area_faces = 0;  // distinct vertices but zero area: kept, counted
  bool changed() const {
    return degenerate_faces_removed || duplicate_faces_removed || unreferenced_vertices_removed ||
           vertex_copies_added;
  }
};

struct RepairedMesh {
  Mesh mesh;  // manifold, no degenerate or duplicate faces
  // For each vertex of `mesh`: the vertex of the input it came from. Copies made to split a
  // non-manifold vertex map to the same input vertex as the original.
  std::vector<VertexId> input_vertex;
  // For each face of `mesh`: its index among the input's faces (after fan triangulation);
  // increasing without spatial_order (faces keep their order).
  std::vector<FaceId> input_face;
  // For each wedge of `mesh`: the wedge of the input it came from (copies made with a vertex
  // copy map to the wedge they copy). Empty when the mesh has no attributes.
  std::vector<WedgeId> input_wedge;
  uint64_t input_vertex_count = 0;  // of the mesh given to repair_mesh
  uint64_t input_face_count = 0;
  RepairReport report;
};

RepairedMesh repair_mesh(const Mesh& input, const RepairOptions& options = {});

// The faces that share a halfedge (a corner's edge in the face's direction) with another face,
// each once, increasing; none in an oriented manifold. Linear in the faces (each vertex's
// outgoing halfedges gathered, those of a vertex with many sorted): the repair's check that a
// split it made is a manifold.
std::vector<FaceId> faces_sharing_a_halfedge(const std::vector<Triangle>& faces,
                                             size_t vertex_count);

}  // namespace parapm
