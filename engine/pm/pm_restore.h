// Giving back the input from a Progressive Mesh: every split applied, the vertex copies the
// repair step made merged back into their originals, and (when the PM kept it) the input's
// vertex and face order. With compare_meshes_exact (mesh_compare.h, included), this is what
// `parapm check` runs to prove a PM lossless.
#pragma once

#include "mesh/mesh.h"
#include "pm/mesh_compare.h"
#include "pm/progressive_mesh.h"

namespace parapm {

// The full-resolution mesh with:
//  1. each copy of vertex_copies merged into its original: the copy's corners point to the
//     original, the copy is removed and the remaining vertices are renumbered compactly in
//     their order;
//  2. when input_vertex_order is present, vertices ordered by their input index (indices the
//     repair step removed are skipped: the numbering stays compact); when input_face_order is
//     present, faces ordered by their input index likewise.
// Wedges are the distinct (vertex, PM wedge) pairs after merging (mesh_assembly.h). This is
// the repaired input (mesh/repaired_input.h) that the PM was built from, up to wedge
// numbering. Runs validate_pm() first; throws Error(kInvalidInput) for a corrupt PM.
Mesh restore_input(const ProgressiveMesh& pm);

}  // namespace parapm
