// Progressive Meshes for the tests of engine/pm: small ones written by hand (each drawn in
// pm_fixtures.cpp, with the fine mesh it must give), and random ones of any size made by
// applying random valid vertex splits to a base mesh (closed or open, so every fan case
// occurs: interior, boundary with vl or vr absent, and vt on a boundary with vs interior).
#pragma once

#include <cstdint>
#include <vector>

#include "pm/progressive_mesh.h"

namespace parapm::testing {

// An open strip with two boundary splits: split 0 has no vr, split 1 has no vl.
ProgressiveMesh strip_pm();
// The full-resolution faces strip_pm() must give.
std::vector<Triangle> strip_full_faces();

// An octahedron (closed) with three interior splits, the third one splitting a vertex that
// the first created. With attributes: texture coordinates, new wedges, and wedge changes.
ProgressiveMesh octahedron_pm(bool attributes = false);

// One split whose vt is a boundary vertex and vs an interior one: in the coarse mesh vs is on
// the boundary and the fan is cut in two by it.
ProgressiveMesh cut_fan_pm();
std::vector<Triangle> cut_fan_full_faces();

struct RandomPmOptions {
  bool closed = true;       // base: an octahedron; else an open grid (a disk)
  bool attributes = false;  // texture coordinates with new wedges and wedge changes
  bool float32 = true;      // positions rounded to float32 (positions_are_float)
  uint64_t seed = 1;
};
ProgressiveMesh random_pm(size_t splits, const RandomPmOptions& options = {});

// Each directed edge is used by at most one face, and no face repeats a vertex.
bool is_oriented_manifold(const std::vector<Triangle>& faces);
// Faces rotated to start at their smallest vertex, sorted: compares face sets.
std::vector<Triangle> canonical_faces(std::vector<Triangle> faces);

}  // namespace parapm::testing
