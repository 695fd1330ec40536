// The repair's copies of each non-manifold input vertex, one per sheet meeting there
// (repair.h rule 4), as groups of vertices of the repaired mesh. The simplifier keeps each
// group at one place: a group moves and leaves the mesh only as a whole, every copy collapsing
// into a copy of one neighbouring group in the same step (a seam collapse,
// Simplifier::join_copies), so that the sheets meet at every level but inside one seam
// collapse's records.
// A membrane, a connected part of the mesh whose every vertex is a copy of a vertex of a part
// that has vertices of its own, and which plugs no hole of such a part (a wall inside a
// surface, a double-sided flap on it: crude scan reconstructions have hundreds; not the two
// sides of a double-sided surface, copies of each other, nor faces filling a hole), holds no
// group: its vertices simplify like any vertex and it may vanish (standard_constraints), and a
// vertex whose other copies all lie on membranes is no copy.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mesh/mesh.h"
#include "mesh/repair.h"

namespace parapm {

struct CopyGroups {
  std::vector<uint32_t> group;  // per vertex: its group, kNoId for a vertex without copies
  std::vector<uint32_t>
      offsets;  // per group g: its members are members[offsets[g], offsets[g + 1])
  std::vector<VertexId> members;  // each group's vertices, increasing
  bool empty() const { return members.empty(); }
  bool is_copy(VertexId v) const { return v < group.size() && group[v] != kNoId; }
  std::span<const VertexId> of(uint32_t g) const {
    return {members.data() + offsets[g], members.data() + offsets[g + 1]};
  }
};

// The groups of `repaired` (the vertices locked_vertices locks), membranes left out; none
// without copies.
CopyGroups copy_groups(const RepairedMesh& repaired);
// The same with its membranes given (membrane_vertices(repaired)).
CopyGroups copy_groups(const RepairedMesh& repaired, const std::vector<uint8_t>& on_membrane);
// Per vertex of `repaired`: 1 on a membrane (empty when `repaired` maps no input vertices).
std::vector<uint8_t> membrane_vertices(const RepairedMesh& repaired);
// The groups an id per vertex names (kNoId: in none; any other value, not necessarily dense:
// the vertices sharing it), numbered by their smallest vertex.
CopyGroups copy_groups_of(std::span<const uint32_t> group_of_vertex);

}  // namespace parapm
