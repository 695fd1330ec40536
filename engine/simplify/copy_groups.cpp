#include "simplify/copy_groups.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "mesh/outgoing_halfedges.h"
#include "util/union_find.h"

namespace parapm {

namespace {

// Per vertex of `mesh`, its connected component (by shared faces) as a root vertex id.
std::vector<uint32_t> component_roots(const Mesh& mesh) {
  UnionFind sets(mesh.vertex_count());
  for (const Triangle& t : mesh.faces) {
    sets.unite(t[0], t[1]);
    sets.unite(t[0], t[2]);
  }
  std::vector<uint32_t> root(mesh.vertex_count());
  for (uint32_t v = 0; v < root.size(); ++v) root[v] = sets.find(v);
  return root;
}

// The boundary edges of `mesh` (a manifold: an edge without the opposite half-edge), each as
// its face's (from, to), in face order. The opposite half-edge is looked up among the
// outgoing half-edges of its tail.
std::vector<std::pair<VertexId, VertexId>> boundary_edges(const Mesh& mesh) {
  const OutgoingHalfedges outgoing = outgoing_halfedges(mesh.faces, mesh.vertex_count());
  const auto has_half_edge = [&](VertexId from, VertexId to) {
    for (const OutgoingHalfedges::Halfedge& h : outgoing.of(from))
      if (h.to == to) return true;
    return false;
  };
  std::vector<std::pair<VertexId, VertexId>> boundary;
  for (const Triangle& t : mesh.faces)
    for (int k = 0; k < 3; ++k)
      if (!has_half_edge(t[(k + 1) % 3], t[k])) boundary.emplace_back(t[k], t[(k + 1) % 3]);
  return boundary;
}

// Per input vertex of `repaired`, its vertices in the repaired mesh.
std::vector<uint32_t> uses_of_input_vertices(const RepairedMesh& repaired) {
  std::vector<uint32_t> uses(repaired.input_vertex_count, 0);
  for (VertexId in : repaired.input_vertex) {
    if (in >= uses.size()) uses.resize(size_t(in) + 1, 0);
    ++uses[in];
  }
  return uses;
}

}  // namespace

std::vector<uint8_t> membrane_vertices(const RepairedMesh& repaired) {
  const size_t vertices = repaired.mesh.vertex_count();
  if (repaired.input_vertex.size() != vertices) return {};
  const std::vector<uint32_t> uses = uses_of_input_vertices(repaired);
  std::vector<uint8_t> on_membrane(vertices, 0);
  if (std::none_of(uses.begin(), uses.end(), [](uint32_t n) { return n > 1; }))
    return on_membrane;  // no copies
  const std::vector<uint32_t> root = component_roots(repaired.mesh);
  std::vector<uint8_t> has_own_vertex(vertices, 0);
  for (VertexId v = 0; v < vertices; ++v)
    if (uses[repaired.input_vertex[v]] == 1) has_own_vertex[root[v]] = 1;
  // Input vertices with a copy on a part that has a vertex of its own.
  std::vector<uint8_t> anchored(uses.size(), 0);
  for (VertexId v = 0; v < vertices; ++v)
    if (has_own_vertex[root[v]]) anchored[repaired.input_vertex[v]] = 1;
  // A part without a vertex of its own is a membrane when each of its vertices has a copy on
  // a part with one (sheets that are all copies of each other, a double-sided surface's two
  // sides, are none: each would vanish with the other) and no boundary edge of it joins the
  // input vertices of such a part's boundary edge (it would plug a hole of that part, which its
  // vanishing would open).
  std::vector<uint8_t> membrane(vertices, 1);
  for (VertexId v = 0; v < vertices; ++v)
    if (has_own_vertex[root[v]] || !anchored[repaired.input_vertex[v]]) membrane[root[v]] = 0;
  bool any = false;
  for (VertexId v = 0; v < vertices && !any; ++v) any = membrane[root[v]];
  if (!any) return on_membrane;
  const auto input_edge = [&](VertexId a, VertexId b) {
    const uint64_t u = repaired.input_vertex[a], w = repaired.input_vertex[b];
    return std::min(u, w) << 32 | std::max(u, w);
  };
  const std::vector<std::pair<VertexId, VertexId>> boundary = boundary_edges(repaired.mesh);
  std::unordered_set<uint64_t> anchored_boundary;
  for (const auto& [a, b] : boundary)
    if (has_own_vertex[root[a]]) anchored_boundary.insert(input_edge(a, b));
  for (const auto& [a, b] : boundary)
    if (membrane[root[a]] && anchored_boundary.count(input_edge(a, b))) membrane[root[a]] = 0;
  for (VertexId v = 0; v < vertices; ++v) on_membrane[v] = membrane[root[v]];
  return on_membrane;
}

CopyGroups copy_groups(const RepairedMesh& repaired) {
  return copy_groups(repaired, membrane_vertices(repaired));
}

CopyGroups copy_groups(const RepairedMesh& repaired, const std::vector<uint8_t>& on_membrane) {
  const size_t vertices = repaired.mesh.vertex_count();
  if (repaired.input_vertex.size() != vertices) return {};
  std::vector<uint32_t> uses = uses_of_input_vertices(repaired);
  // A membrane's vertices drop out of the count, so that a vertex whose other copies all lie on
  // membranes is no copy either.
  for (VertexId v = 0; v < vertices; ++v)
    if (on_membrane[v]) --uses[repaired.input_vertex[v]];
  std::vector<uint32_t> input_of_copy(vertices, kNoId);
  for (VertexId v = 0; v < vertices; ++v)
    if (!on_membrane[v] && uses[repaired.input_vertex[v]] > 1)
      input_of_copy[v] = repaired.input_vertex[v];
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
