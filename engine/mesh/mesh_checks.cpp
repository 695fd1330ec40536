// Topology statistics and the oriented-manifold invariant. The method is the textbook one,
// deliberately different from repair.cpp's bucketed walk: the directed edges of all faces
// are sorted by their undirected key, which groups the faces of each edge; the corners of a
// vertex are joined by a union-find across that vertex's manifold edges. Unions only ever
// join corners of the same vertex, so a vertex has as many fans as it has root corners.
#include "mesh/mesh_checks.h"

#include <algorithm>
#include <numeric>

#include "util/error.h"
#include "util/union_find.h"

namespace parapm {
namespace {

// Directed edge of face `halfedge / 3`, from its corner `halfedge % 3` to the next corner.
struct DirectedEdge {
  uint64_t key;  // undirected: lower end << 32 | higher end
  uint32_t halfedge;
  VertexId lo() const { return VertexId(key >> 32); }
  VertexId hi() const { return VertexId(key); }
  bool operator<(const DirectedEdge& other) const {
    return key != other.key ? key < other.key : halfedge < other.halfedge;
  }
};

bool is_degenerate(const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

std::string face_list(const std::vector<DirectedEdge>& edges, size_t begin, size_t end) {
  std::string out;
  const size_t shown = std::min<size_t>(end - begin, 8);
  for (size_t k = 0; k < shown; ++k) {
    if (k) out += ", ";
    out += std::to_string(edges[begin + k].halfedge / 3);
  }
  if (end - begin > shown) out += ", ...";
  return out;
}

// Computes the statistics and describes the first problem that keeps the mesh from being an
// oriented manifold (empty when there is none). Corners must be in range.
TopologyStats analyze(const Mesh& mesh, std::string* problem) {
  const std::vector<Triangle>& faces = mesh.faces;
  const size_t n = mesh.vertex_count();
  TopologyStats stats;
  stats.vertices = n;
  stats.faces = faces.size();
  if (faces.size() > (size_t(kNoId) - 1) / 3) {
    throw Error(ErrorCode::kResourceExhausted, "mesh has too many faces to check");
  }

  std::vector<DirectedEdge> edges;
  edges.reserve(3 * faces.size());
  for (size_t f = 0; f < faces.size(); ++f) {
    const Triangle& t = faces[f];
    if (is_degenerate(t)) {
      if (stats.degenerate_faces++ == 0 && problem->empty()) {
        *problem = "face " + std::to_string(f) + " is degenerate (" + std::to_string(t[0]) + ", " +
                   std::to_string(t[1]) + ", " + std::to_string(t[2]) + ")";
      }
      continue;
    }
    for (int i = 0; i < 3; ++i) {
      const VertexId u = t[i], v = t[(i + 1) % 3];
      edges.push_back({uint64_t(std::min(u, v)) << 32 | std::max(u, v), uint32_t(3 * f + i)});
    }
  }
  std::sort(edges.begin(), edges.end());

  // Edges: classify each group of equal keys; join the corners across manifold edges.
  UnionFind corners(3 * faces.size());
  for (size_t begin = 0, end = 0; begin < edges.size(); begin = end) {
    end = begin + 1;
    while (end < edges.size() && edges[end].key == edges[begin].key) ++end;
    ++stats.edges;
    if (end - begin == 1) {
      ++stats.boundary_edges;
      continue;
    }
    const uint32_t h1 = edges[begin].halfedge, h2 = edges[begin + 1].halfedge;
    const uint32_t f1 = h1 / 3, i1 = h1 % 3, f2 = h2 / 3, i2 = h2 % 3;
    const bool opposite = faces[f1][i1] == faces[f2][(i2 + 1) % 3];
    if (end - begin == 2 && opposite) {
      // h1 goes u -> v, h2 goes v -> u: join the corners at u, and the corners at v.
      corners.unite(h1, 3 * f2 + (i2 + 1) % 3);
      corners.unite(3 * f1 + (i1 + 1) % 3, h2);
      continue;
    }
    ++stats.nonmanifold_edges;
    if (end - begin == 2) ++stats.inconsistent_edges;
    if (problem->empty()) {
      const std::string edge_name = "edge (" + std::to_string(edges[begin].lo()) + ", " +
                                    std::to_string(edges[begin].hi()) + ")";
      if (end - begin == 2) {
        *problem = edge_name + " is used in the same direction by faces " + std::to_string(f1) +
                   " and " + std::to_string(f2);
      } else {
        *problem = edge_name + " has " + std::to_string(end - begin) +
                   " faces: " + face_list(edges, begin, end);
      }
    }
  }

  // Fans: count the root corners of each vertex.
  std::vector<uint32_t> fans(n, 0);
  for (size_t f = 0; f < faces.size(); ++f) {
    if (is_degenerate(faces[f])) continue;
    for (int i = 0; i < 3; ++i) {
      const uint32_t c = uint32_t(3 * f + i);
      if (corners.find(c) == c) ++fans[faces[f][i]];
    }
  }
  uint64_t referenced = 0;
  VertexId first_nonmanifold = kNoId;
  for (size_t v = 0; v < n; ++v) {
    if (fans[v] > 0) ++referenced;
    if (fans[v] > 1 && stats.nonmanifold_vertices++ == 0) first_nonmanifold = VertexId(v);
  }
  if (first_nonmanifold != kNoId && problem->empty()) {
    // Name the lowest faces of its first two fans (the corners are visited in face order).
    std::vector<uint32_t> roots, first_faces;
    for (size_t f = 0; f < faces.size() && roots.size() < 2; ++f) {
      for (int i = 0; i < 3; ++i) {
        if (faces[f][i] != first_nonmanifold || is_degenerate(faces[f])) continue;
        const uint32_t root = corners.find(uint32_t(3 * f + i));
        if (std::find(roots.begin(), roots.end(), root) != roots.end()) continue;
        roots.push_back(root);
        first_faces.push_back(uint32_t(f));
      }
    }
    const uint32_t count = fans[first_nonmanifold];
    *problem = "vertex " + std::to_string(first_nonmanifold) + " has " + std::to_string(count) +
               " separate fans of faces (holding faces " + std::to_string(first_faces[0]) + ", " +
               std::to_string(first_faces[1]) + (count > 2 ? ", ...)" : ")");
  }
  stats.isolated_vertices = n - referenced;

  // Components: vertices joined by the faces.
  UnionFind vertices(n);
  std::vector<bool> used(n, false);
  for (const Triangle& t : faces) {
    if (is_degenerate(t)) continue;
    vertices.unite(t[0], t[1]);
    vertices.unite(t[0], t[2]);
    for (VertexId v : t) used[v] = true;
  }
  for (size_t v = 0; v < n; ++v) {
    if (used[v] && vertices.find(uint32_t(v)) == v) ++stats.components;
  }
  stats.euler_characteristic =
      int64_t(referenced) - int64_t(stats.edges) + int64_t(stats.faces - stats.degenerate_faces);
  return stats;
}

// The first corner out of range, described; empty when all are in range.
std::string range_problem(const Mesh& mesh) {
  const size_t n = mesh.vertex_count();
  if (n >= kNoId) return "mesh has too many vertices (" + std::to_string(n) + ")";
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int i = 0; i < 3; ++i) {
      if (mesh.faces[f][i] >= n) {
        return "face " + std::to_string(f) + " corner " + std::to_string(i) + " refers to vertex " +
               std::to_string(mesh.faces[f][i]) + ", but the mesh has " + std::to_string(n) +
               " vertices";
      }
    }
  }
  return {};
}

}  // namespace

TopologyStats topology_stats(const Mesh& mesh) {
  if (std::string problem = range_problem(mesh); !problem.empty()) throw_invalid(problem);
  std::string ignored;
  return analyze(mesh, &ignored);
}

bool is_oriented_manifold(const Mesh& mesh, std::string* why) {
  std::string problem = range_problem(mesh);
  if (problem.empty()) analyze(mesh, &problem);
  if (why) *why = problem;
  return problem.empty();
}

bool wedges_are_consistent(const Mesh& mesh, std::string* why) {
  auto fail = [&](const std::string& problem) {
    if (why) *why = problem;
    return false;
  };
  const size_t wedges = mesh.wedge_count();
  if (!mesh.layout.any()) {
    if (wedges || !mesh.wedge_values.empty() || !mesh.face_wedges.empty()) {
      return fail("mesh has no attribute channels but " + std::to_string(wedges) + " wedges, " +
                  std::to_string(mesh.wedge_values.size()) + " wedge values and " +
                  std::to_string(mesh.face_wedges.size()) + " face wedge triples");
    }
    if (why) why->clear();
    return true;
  }
  const size_t floats = size_t(mesh.layout.floats_per_wedge());
  if (mesh.wedge_values.size() != wedges * floats) {
    return fail("wedge_values has " + std::to_string(mesh.wedge_values.size()) +
                " floats, expected " + std::to_string(wedges) + " wedges x " +
                std::to_string(floats));
  }
  if (mesh.face_wedges.size() != mesh.faces.size()) {
    return fail("face_wedges has " + std::to_string(mesh.face_wedges.size()) + " entries for " +
                std::to_string(mesh.faces.size()) + " faces");
  }
  for (size_t w = 0; w < wedges; ++w) {
    if (mesh.wedge_vertex[w] >= mesh.vertex_count()) {
      return fail("wedge " + std::to_string(w) + " belongs to vertex " +
                  std::to_string(mesh.wedge_vertex[w]) + ", but the mesh has " +
                  std::to_string(mesh.vertex_count()) + " vertices");
    }
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int i = 0; i < 3; ++i) {
      const WedgeId w = mesh.face_wedges[f][i];
      auto corner = [&] { return "face " + std::to_string(f) + " corner " + std::to_string(i); };
      if (w >= wedges) {
        return fail(corner() + " uses wedge " + std::to_string(w) + ", but the mesh has " +
                    std::to_string(wedges) + " wedges");
      }
      if (mesh.wedge_vertex[w] != mesh.faces[f][i]) {
        return fail(corner() + " uses wedge " + std::to_string(w) + " of vertex " +
                    std::to_string(mesh.wedge_vertex[w]) + ", but the corner's vertex is " +
                    std::to_string(mesh.faces[f][i]));
      }
    }
  }
  if (why) why->clear();
  return true;
}

}  // namespace parapm
