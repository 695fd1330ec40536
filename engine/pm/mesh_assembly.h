// Turns a level of a Progressive Mesh (positions, faces, and the PM's wedge ids per corner)
// into a plain Mesh whose wedge model is consistent: every wedge belongs to one vertex.
//
// Why this is needed: a vsplit moves faces from vs to vt without touching their corner wedges
// (progressive_mesh.h), so at some levels one PM wedge is used at corners of two vertices.
// The Mesh gets one wedge per distinct (corner vertex, PM wedge) pair, carrying the PM
// wedge's values. Wedges no corner uses are dropped.
#pragma once

#include <array>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

// `face_wedges` (PM wedge ids per corner) and `wedge_values` (floats_per_wedge per PM wedge)
// are ignored when layout.any() is false. Output wedges are ordered by PM wedge id, and for
// one PM wedge the vertex met first in face order comes first, then the others by id; at full
// resolution of a PM whose wedges each belong to one vertex, that is the PM's own numbering
// minus the unused wedges. `wedge_source`, when given, receives the PM wedge of each output
// wedge. Throws Error(kInvalidInput) when a corner names a wedge without values.
Mesh assemble_mesh(std::vector<Vec3> positions, std::vector<Triangle> faces,
                   const std::vector<std::array<WedgeId, 3>>& face_wedges,
                   const std::vector<float>& wedge_values, const AttributeLayout& layout,
                   bool positions_are_float, std::vector<WedgeId>* wedge_source = nullptr);

}  // namespace parapm
