// Memory locality for the engine: vertices renumbered along a space-filling curve (Morton
// order: the bits of the three quantised coordinates interleaved), faces by their first vertex
// in that order, wedges by their vertex. The simplifier, the energy's points and the subset
// jobs then touch neighbouring memory when they touch neighbouring surface.
//
// Method: G. M. Morton, "A computer oriented geodetic data base and a new technique in file
// sequencing", IBM report, 1966 (the Z-order curve); used for mesh locality as in, e.g.,
// S.-E. Yoon et al., "Cache-Oblivious Mesh Layouts", SIGGRAPH 2005, which orders better than a
// plain curve but costs a graph optimisation: the curve is O(V log V) and enough here.
//
// Why: a collapse reads its star (faces, corners, positions, point lists, queue entries), and
// on a mesh of hundreds of thousands of faces most of those reads miss the caches unless
// neighbours on the surface are neighbours in memory: builds are 6-9% faster on a mesh already
// in scan order, and a shuffled file no longer costs a quarter more (decisions/notebook-2026-11.md,
// "Memory order"). The order is the repair's last step
// (RepairOptions::spatial_order), so every path (CLI, service, tests through repair_mesh)
// simplifies the same numbering, and the PM renumbers vertices in its own order anyway.
//
// Deterministic: ties (equal codes, faces with the same first vertex) keep their previous
// order, so ordering an ordered mesh changes nothing.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/mesh.h"
#include "util/chunked_loops.h"

namespace parapm {

struct RepairedMesh;

// The 63-bit Morton code of p in `box` (21 bits per axis). An axis of zero extent, or a point
// outside the box, clamps.
uint64_t morton_code(const Vec3& p, const Box& box);

// new_id[old] for every vertex of `mesh`: ranked by Morton code, ties by id. In `loops`'
// chunks, the same order.
std::vector<VertexId> spatial_vertex_order(const Mesh& mesh);
std::vector<VertexId> spatial_vertex_order(const Mesh& mesh, ChunkedLoops& loops);

// Renumbers repaired.mesh's vertices, faces and wedges as above and composes the maps back to
// the input (input_vertex, input_face, input_wedge), so that the repaired mesh means what it
// meant. A mesh with one wedge per vertex (wedge i of vertex i) keeps that property. In `loops`'
// chunks, the same mesh and maps.
void order_spatially(RepairedMesh& repaired);
void order_spatially(RepairedMesh& repaired, ChunkedLoops& loops);

}  // namespace parapm
