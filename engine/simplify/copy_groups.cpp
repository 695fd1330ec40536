#include "simplify/copy_groups.h"

#include <unordered_map>

namespace parapm {

CopyGroups copy_groups(const RepairedMesh& repaired) {
  const size_t vertices = repaired.mesh.vertex_count();
  if (repaired.input_vertex.size() != vertices) return {};
  // Per vertex its input vertex, when that one has more than one vertex.
  std::vector<uint32_t> uses(repaired.input_vertex_count, 0);
  for (VertexId in : repaired.input_vertex) {
    if (in >= uses.size()) uses.resize(size_t(in) + 1, 0);
    ++uses[in];
  }
  std::vector<uint32_t> input_of_copy(vertices, kNoId);
  for (VertexId v = 0; v < vertices; ++v)
    if (uses[repaired.input_vertex[v]] > 1) input_of_copy[v] = repaired.input_vertex[v];
  return copy_groups_of(input_of_copy);
}

CopyGroups copy_groups_of(std::span<const uint32_t> group_of_vertex) {
  CopyGroups groups;
  // Each id's group number, in the order of the ids' first vertices.
  std::unordered_map<uint32_t, uint32_t> number;
  groups.group.assign(group_of_vertex.size(), kNoId);
  groups.offsets.push_back(0);
  std::vector<uint32_t> sizes;
  for (VertexId v = 0; v < group_of_vertex.size(); ++v) {
    const uint32_t id = group_of_vertex[v];
    if (id == kNoId) continue;
    const auto [at, added] = number.try_emplace(id, uint32_t(sizes.size()));
    if (added) sizes.push_back(0);
    groups.group[v] = at->second;
    ++sizes[at->second];
  }
  for (uint32_t size : sizes) groups.offsets.push_back(groups.offsets.back() + size);
  // Members by counting sort: each group's in increasing vertex order.
  groups.members.resize(groups.offsets.back());
  std::vector<uint32_t> next(groups.offsets.begin(), groups.offsets.end() - 1);
  for (VertexId v = 0; v < groups.group.size(); ++v)
    if (groups.group[v] != kNoId) groups.members[next[groups.group[v]]++] = v;
  if (groups.members.empty()) groups.group.clear();
  return groups;
}

}  // namespace parapm
