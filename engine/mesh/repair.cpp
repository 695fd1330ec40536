// Validation and repair of an indexed triangle mesh; the rules are in repair.h.
//
// Method:
//  - A. Guéziec, G. Taubin, F. Lazarus, W. Horn, "Cutting and Stitching: Converting Sets of
//    Polygons to Manifold Surfaces", IEEE TVCG 7(2), 2001: the cutting half. Singular edges
//    are cut, then each vertex is copied once per extra fan of faces around it. We do not
//    stitch: stitching changes the input's connectivity, and the PM must give it back.
//  - H. Hoppe, "Progressive Meshes", SIGGRAPH 96, section 3.1: wedges. A copied vertex takes
//    copies of the wedges its corners use, so that every wedge still belongs to one vertex.
//
// Why cutting edges is enough (the "non-disk vertex" question). Around a vertex v each corner
// has two edges at v: an outgoing one (v -> a) and an incoming one (b -> v). A manifold edge
// has exactly one face in each direction, so it joins the outgoing edge of one corner to the
// incoming edge of another, and each corner has at most one neighbour on each side. A fan is
// therefore a simple chain or a simple cycle of corners, consistently oriented, and its edges
// at v lead to distinct vertices (an indexed mesh has one edge {v, a}): a half-disk or a disk.
// Two fans cannot be joined through a manifold edge, by definition of a fan.
// The cut edges cannot break this either: a face that uses a cut edge v -> a has no
// neighbour past its outgoing edge at v, so it is the clockwise end of its chain at v; a chain
// has one such end, so two faces that use a cut edge in the same direction always end up in
// different fans, at v and at a, hence on different copies. After the split each edge of the
// output has at most one face per direction: manifold. A cut edge may remain an edge of the
// output with two faces (say a tetrahedron with a fourth face on one of its edges: the
// tetrahedron's two faces on that edge stay in one fan at both ends and keep their vertices,
// only the extra face moves to copies); that closes the chain into a disk, which is fine.
// Two of the pairings step 4a makes across a non-manifold edge for faces laid back to back
// keep this too: they join faces without their reverse on that edge (its other faces are
// reverse pairs), or a face F whose every edge holds three faces. A face cut off there has its
// reverse on every edge of it, so it is joined to its reverse or to nothing: never to a face
// F (whose edges hold three faces, a flap's edge at least four) nor to the surface, so it
// shares no fan with a face it was cut from. The third, side with side across an edge of two
// reverse pairs, does not: through a fold (two double-sided triangles on one edge) a side can
// come round to the other at both ends of the edge, so step 4 checks the split and makes it
// again without that pairing around the faces that share a halfedge.
// mesh_checks.h verifies the result independently; the tests run it on every mesh.
//
// Cost: counting sorts by vertex, then sorts inside each vertex's bucket (its few faces or
// edges): O(F log(max valence)) time; about 60 bytes per face of scratch memory. No hashing,
// ties broken by index: the output depends only on the input. The passes over faces and
// vertices may run in chunks side by side (RepairOptions::loops), each over a range of faces
// or of vertices, its items sent to it once (items_of_ranges), writing only its own: the same
// output.
#include "mesh/repair.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cmath>
#include <string>
#include <tuple>

#include "mesh/outgoing_halfedges.h"
#include "mesh/spatial_order.h"
#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm {
namespace {

// ---------------------------------------------------------------------------------------
// Messages.

std::string number(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

template <class T>
std::string tuple_text(const T* values, int count) {
  std::string out = "(";
  for (int k = 0; k < count; ++k) {
    if (k) out += ", ";
    out += number(double(values[k]));
  }
  return out + ")";
}

// ---------------------------------------------------------------------------------------
// Step 1: refuse what cannot be repaired.

void check_finite_positions(const Mesh& mesh) {
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3& p = mesh.positions[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      throw_invalid("vertex " + std::to_string(v) + " has a non-finite coordinate " +
                    tuple_text(p.data(), 3));
    }
  }
}

void check_corners(const Mesh& mesh) {
  const size_t n = mesh.vertex_count();
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int i = 0; i < 3; ++i) {
      if (mesh.faces[f][i] >= n) {
        throw_invalid("face " + std::to_string(f) + " corner " + std::to_string(i) +
                      " refers to vertex " + std::to_string(mesh.faces[f][i]) +
                      ", but the mesh has " + std::to_string(n) + " vertices");
      }
    }
  }
}

void check_wedges(const Mesh& mesh) {
  const size_t wedges = mesh.wedge_count();
  if (!mesh.layout.any()) {
    // No channel, no wedges: a reader that filled wedges without a layout has a bug that
    // would otherwise surface far from here.
    if (wedges || !mesh.wedge_values.empty() || !mesh.face_wedges.empty()) {
      throw_invalid("mesh has no attribute channels but " + std::to_string(wedges) + " wedges, " +
                    std::to_string(mesh.wedge_values.size()) + " wedge values and " +
                    std::to_string(mesh.face_wedges.size()) + " face wedge triples");
    }
    return;
  }
  if (wedges >= kNoId) {
    throw Error(ErrorCode::kResourceExhausted,
                "mesh has too many wedges (" + std::to_string(wedges) + ")");
  }
  const int floats = mesh.layout.floats_per_wedge();
  if (mesh.wedge_values.size() != wedges * size_t(floats)) {
    throw_invalid("wedge_values has " + std::to_string(mesh.wedge_values.size()) +
                  " floats, expected " + std::to_string(wedges) + " wedges x " +
                  std::to_string(floats) + " floats");
  }
  if (mesh.face_wedges.size() != mesh.faces.size()) {
    throw_invalid("face_wedges has " + std::to_string(mesh.face_wedges.size()) +
                  " entries, expected one per face (" + std::to_string(mesh.faces.size()) + ")");
  }
  struct Channel {
    bool present;
    int offset, count;
    const char* name;
  };
  const AttributeLayout& layout = mesh.layout;
  const Channel channels[] = {{layout.normals, layout.normal_offset(), 3, "normal"},
                              {layout.texcoords, layout.texcoord_offset(), 2, "texcoord"},
                              {layout.colors, layout.color_offset(), 4, "color"}};
  for (size_t w = 0; w < wedges; ++w) {
    const VertexId v = mesh.wedge_vertex[w];
    if (v >= mesh.vertex_count()) {
      throw_invalid("wedge " + std::to_string(w) + " belongs to vertex " + std::to_string(v) +
                    ", but the mesh has " + std::to_string(mesh.vertex_count()) + " vertices");
    }
    const float* values = mesh.wedge(WedgeId(w));
    for (const Channel& channel : channels) {
      if (!channel.present) continue;
      for (int k = 0; k < channel.count; ++k) {
        if (!std::isfinite(values[channel.offset + k])) {
          throw_invalid("wedge " + std::to_string(w) + " (vertex " + std::to_string(v) +
                        ") has a non-finite " + channel.name + " " +
                        tuple_text(values + channel.offset, channel.count));
        }
      }
    }
  }
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    for (int i = 0; i < 3; ++i) {
      const WedgeId w = mesh.face_wedges[f][i];
      auto corner = [&] { return "face " + std::to_string(f) + " corner " + std::to_string(i); };
      if (w >= wedges) {
        throw_invalid(corner() + " uses wedge " + std::to_string(w) + ", but the mesh has " +
                      std::to_string(wedges) + " wedges");
      }
      if (mesh.wedge_vertex[w] != mesh.faces[f][i]) {
        throw_invalid(corner() + " (vertex " + std::to_string(mesh.faces[f][i]) + ") uses wedge " +
                      std::to_string(w) + ", which belongs to vertex " +
                      std::to_string(mesh.wedge_vertex[w]));
      }
    }
  }
}

void validate(const Mesh& mesh) {
  // Ids must stay below kNoId, and corner ids (3 * face + corner) must fit in 32 bits.
  if (mesh.vertex_count() >= kNoId) {
    throw Error(ErrorCode::kResourceExhausted,
                "mesh has too many vertices (" + std::to_string(mesh.vertex_count()) + ")");
  }
  if (mesh.face_count() > (size_t(kNoId) - 1) / 3) {
    throw Error(ErrorCode::kResourceExhausted,
                "mesh has too many faces (" + std::to_string(mesh.face_count()) + ")");
  }
  check_finite_positions(mesh);
  check_corners(mesh);
  check_wedges(mesh);
}

// ---------------------------------------------------------------------------------------
// Counting sort by vertex, the building block of steps 2 and 4 (run on each range of vertices
// for the items of that range, items_of_ranges, keys counted from the range's first vertex):
// for each item i whose key_of(i) is not kNoId, value_of(i) is stored in bucket key_of(i), in
// increasing i inside a bucket; bucket k is values[starts[k] .. starts[k + 1]). The values
// carry what the sort inside a bucket compares, so that it does not go back to the faces.

template <class Value, class KeyOf, class ValueOf>
void bucket_by_vertex(size_t items, size_t vertices, KeyOf key_of, ValueOf value_of,
                      std::vector<Value>* values, std::vector<uint32_t>* starts) {
  starts->assign(vertices + 1, 0);
  for (size_t i = 0; i < items; ++i) {
    const VertexId k = key_of(i);
    if (k != kNoId) ++(*starts)[k + 1];
  }
  for (size_t k = 0; k < vertices; ++k) (*starts)[k + 1] += (*starts)[k];
  values->resize((*starts)[vertices]);
  std::vector<uint32_t> next(starts->begin(), starts->end() - 1);
  for (size_t i = 0; i < items; ++i) {
    const VertexId k = key_of(i);
    if (k != kNoId) (*values)[next[k]++] = value_of(i);
  }
}

// ---------------------------------------------------------------------------------------
// Step 2: degenerate and duplicate faces.

struct FaceFilter {
  std::vector<FaceId> kept;  // input face ids, increasing
  uint64_t degenerate = 0;
  uint64_t duplicate = 0;
};

FaceFilter filter_faces(const std::vector<Triangle>& faces, size_t vertices, ChunkedLoops& loops) {
  // Rotate each face so that its lowest vertex comes first: two faces are duplicates exactly
  // when their rotated triples are equal. Degenerate faces get kNoId, which keeps them out of
  // the buckets.
  std::vector<Triangle> rotated = filled_touched(faces.size(), Triangle{}, loops);
  loops.run(faces.size(), [&](size_t begin, size_t end) {
    for (size_t f = begin; f < end; ++f) {
      const Triangle& t = faces[f];
      if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
        rotated[f] = {kNoId, kNoId, kNoId};
        continue;
      }
      const int first = t[0] < t[1] ? (t[0] < t[2] ? 0 : 2) : (t[1] < t[2] ? 1 : 2);
      rotated[f] = {t[first], t[(first + 1) % 3], t[(first + 2) % 3]};
    }
  });
  FaceFilter filter;
  // Per range of vertices, its faces bucketed by their lowest vertex, holding (second vertex,
  // third vertex, face). Inside a bucket equal triples become adjacent once sorted; the lowest
  // face id of each run is kept.
  std::vector<uint8_t> removed = filled_touched<uint8_t>(faces.size(), 0, loops);
  std::vector<uint64_t> duplicates(loops.ranges(vertices), 0);
  const auto faces_of_range =
      items_of_ranges(loops, faces.size(), vertices, [&](size_t f) { return rotated[f][0]; });
  loops.run_indexed(vertices, [&](size_t range, size_t first, size_t last) {
    const RangeItems mine(faces_of_range, range, faces.size());
    std::vector<std::array<uint32_t, 3>> entries;
    std::vector<uint32_t> starts;
    bucket_by_vertex(
        mine.size(), last - first,
        [&](size_t i) {  // kNoId stays kNoId: a degenerate face is in a one-range loop only
          return rotated[mine[i]][0] == kNoId ? kNoId : VertexId(rotated[mine[i]][0] - first);
        },
        [&](size_t i) {
          return std::array<uint32_t, 3>{rotated[mine[i]][1], rotated[mine[i]][2], mine[i]};
        },
        &entries, &starts);
    for (size_t v = 0; v < last - first; ++v) {
      const auto begin = entries.begin() + starts[v], end = entries.begin() + starts[v + 1];
      if (end - begin < 2) continue;
      std::sort(begin, end);
      for (auto it = begin + 1; it != end; ++it) {
        if ((*it)[0] == (*(it - 1))[0] && (*it)[1] == (*(it - 1))[1]) {
          removed[(*it)[2]] = 1;
          ++duplicates[range];
        }
      }
    }
  });
  for (const Triangle& t : rotated) filter.degenerate += t[0] == kNoId ? 1 : 0;
  for (uint64_t d : duplicates) filter.duplicate += d;
  filter.kept.reserve(faces.size() - filter.degenerate - filter.duplicate);
  for (size_t f = 0; f < faces.size(); ++f) {
    if (rotated[f][0] != kNoId && !removed[f]) filter.kept.push_back(FaceId(f));
  }
  return filter;
}

bool has_zero_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const Vec3 w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  return u[1] * w[2] - u[2] * w[1] == 0 && u[2] * w[0] - u[0] * w[2] == 0 &&
         u[0] * w[1] - u[1] * w[0] == 0;
}

// ---------------------------------------------------------------------------------------
// Step 3: keep the kept faces' vertices (or all of them), renumbered in order, with their
// wedges. Fills everything of `out` but the manifold split.

void compact(const Mesh& input, const std::vector<FaceId>& kept, const RepairOptions& options,
             RepairedMesh* out, ChunkedLoops& loops) {
  const size_t n = input.vertex_count();
  // Marked from the kept faces' corners, chunks side by side (relaxed stores of the same 1).
  std::vector<uint8_t> referenced =
      filled_touched<uint8_t>(n, options.keep_unreferenced ? 1 : 0, loops);
  if (!options.keep_unreferenced)
    loops.run(kept.size(), [&](size_t begin, size_t end) {
      for (size_t j = begin; j < end; ++j)
        for (VertexId v : input.faces[kept[j]])
          std::atomic_ref<uint8_t>(referenced[v]).store(1, std::memory_order_relaxed);
    });
  KeptItems vertices = number_kept(loops, n, [&](size_t v) { return referenced[v] != 0; });
  out->report.unreferenced_vertices_removed = n - vertices.old_id.size();
  Mesh& mesh = out->mesh;
  resize_touched(mesh.positions, vertices.old_id.size(), loops);
  loops.run(vertices.old_id.size(), [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) mesh.positions[v] = input.positions[vertices.old_id[v]];
  });
  const std::vector<VertexId>& new_vertex = vertices.new_id;
  resize_touched(mesh.faces, kept.size(), loops);
  loops.run(kept.size(), [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      const Triangle& t = input.faces[kept[j]];
      mesh.faces[j] = {new_vertex[t[0]], new_vertex[t[1]], new_vertex[t[2]]};
    }
  });
  out->input_face = kept;

  mesh.layout = input.layout;
  mesh.positions_are_float = input.positions_are_float;
  if (!input.layout.any()) {
    out->input_vertex = std::move(vertices.old_id);
    return;
  }
  KeptItems wedges = number_kept(loops, input.wedge_count(), [&](size_t w) {
    return new_vertex[input.wedge_vertex[w]] != kNoId;
  });
  const size_t floats = size_t(input.layout.floats_per_wedge());
  resize_touched(mesh.wedge_vertex, wedges.old_id.size(), loops);
  resize_touched(mesh.wedge_values, wedges.old_id.size() * floats, loops);
  loops.run(wedges.old_id.size(), [&](size_t begin, size_t end) {
    for (size_t w = begin; w < end; ++w) {
      const WedgeId old = wedges.old_id[w];
      mesh.wedge_vertex[w] = new_vertex[input.wedge_vertex[old]];
      const float* values = input.wedge(old);
      std::copy_n(values, floats, mesh.wedge_values.begin() + ptrdiff_t(w * floats));
    }
  });
  const std::vector<WedgeId>& new_wedge = wedges.new_id;
  resize_touched(mesh.face_wedges, kept.size(), loops);
  loops.run(kept.size(), [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      const auto& fw = input.face_wedges[kept[j]];
      mesh.face_wedges[j] = {new_wedge[fw[0]], new_wedge[fw[1]], new_wedge[fw[2]]};
    }
  });
  out->input_vertex = std::move(vertices.old_id);
  out->input_wedge = std::move(wedges.old_id);
}

// ---------------------------------------------------------------------------------------
// Step 4a: pair the faces across manifold edges. Halfedge h = 3 * face + corner goes from
// that corner to the next; twin[h] is the halfedge of the other face of a manifold edge, or
// kNoId on the boundary and along cut edges.

VertexId tail(const std::vector<Triangle>& faces, uint32_t h) { return faces[h / 3][h % 3]; }
VertexId head(const std::vector<Triangle>& faces, uint32_t h) {
  return faces[h / 3][(h % 3 + 1) % 3];
}

// Faces laid back to back on a surface: a face and its reverse (the same vertices in the
// opposite order; same-order duplicates are gone by rule 2) make the surface's edges
// non-manifold, so that cutting every such edge cuts holes and slits into the surface. Three
// patterns keep the surface joined and cut off only the faces laid on it:
//  - an edge whose faces are reverse pairs but for two, in opposite directions: those two are
//    paired (a double-sided flap standing on the surface's edge);
//  - an edge of exactly two reverse pairs (a double-sided surface): each face is paired with
//    the face against it that is not its reverse, each side with itself, unless the edge's
//    halfedges are marked in `sides_apart` (empty: none is);
//  - a face F with its reverse R on every edge of F, each edge holding exactly F, R and one
//    more face N against F: F is paired with each N, and R, on none, becomes a part of its own
//    (a back face laid on the surface's face F).
// `edges` are the halfedges of the non-manifold edges, `offsets` where each edge's begin.
// Returns whether the second pattern paired any edge (only it can leave a split that is not a
// manifold: this file's opening comment).
bool pair_faces_beside_their_reverses(const std::vector<Triangle>& faces,
                                      const std::vector<uint32_t>& edges,
                                      const std::vector<uint32_t>& offsets,
                                      const std::vector<uint8_t>& sides_apart,
                                      std::vector<uint32_t>& twin) {
  if (edges.empty()) return false;
  bool sides_paired = false;
  // Each face on a non-manifold edge (once, though it may hold three) and its vertex set:
  // reverses share a set.
  std::vector<std::pair<std::array<VertexId, 3>, uint32_t>> by_vertices;  // (sorted, face)
  std::vector<uint8_t> listed(faces.size(), 0);
  for (uint32_t h : edges) {
    if (listed[h / 3]) continue;
    listed[h / 3] = 1;
    std::array<VertexId, 3> sorted = faces[h / 3];
    std::sort(sorted.begin(), sorted.end());
    by_vertices.emplace_back(sorted, h / 3);
  }
  std::sort(by_vertices.begin(), by_vertices.end());
  // Per face on a non-manifold edge, its reverse: the first other face of its vertex set.
  std::vector<uint32_t> reverse(faces.size(), kNoId);
  for (size_t i = 0, end = 0; i < by_vertices.size(); i = end) {
    while (end < by_vertices.size() && by_vertices[end].first == by_vertices[i].first) ++end;
    const uint32_t first = by_vertices[i].second;
    const uint32_t second = end - i > 1 ? by_vertices[i + 1].second : kNoId;
    for (size_t k = i; k < end; ++k) reverse[by_vertices[k].second] = k == i ? second : first;
  }
  const auto reverse_of = [&](uint32_t f) { return reverse[f]; };
  const auto on_edge = [&](uint32_t e, uint32_t f) {
    for (uint32_t i = offsets[e]; i < offsets[e + 1]; ++i)
      if (edges[i] / 3 == f) return true;
    return false;
  };
  // Per halfedge, its non-manifold edge (kNoId: none).
  std::vector<uint32_t> edge_of(3 * faces.size(), kNoId);
  for (uint32_t e = 0; e + 1 < offsets.size(); ++e)
    for (uint32_t i = offsets[e]; i < offsets[e + 1]; ++i)
      if (edge_of[edges[i]] == kNoId) edge_of[edges[i]] = e;
  const auto edge_at = [&](uint32_t h) { return edge_of[h]; };

  for (uint32_t e = 0; e + 1 < offsets.size(); ++e) {
    uint32_t single[3], count = 0;
    for (uint32_t i = offsets[e]; i < offsets[e + 1] && count < 3; ++i) {
      const uint32_t r = reverse_of(edges[i] / 3);
      if (r == kNoId || !on_edge(e, r)) single[count++] = edges[i];
    }
    if (count == 2 && offsets[e + 1] - offsets[e] > 2 &&
        tail(faces, single[0]) == head(faces, single[1])) {
      twin[single[0]] = single[1];
      twin[single[1]] = single[0];
    }
    // Two reverse pairs: each side of a double-sided surface paired with itself (the first
    // face with the face against it that is not its reverse), unless kept apart.
    if (count == 0 && offsets[e + 1] - offsets[e] == 4 &&
        std::none_of(edges.begin() + offsets[e], edges.begin() + offsets[e + 1],
                     [&](uint32_t h) { return !sides_apart.empty() && sides_apart[h]; })) {
      const uint32_t h0 = edges[offsets[e]], r0 = reverse_of(h0 / 3);
      uint32_t hr = kNoId, across = kNoId, other = kNoId;
      for (uint32_t i = offsets[e]; i < offsets[e + 1]; ++i) {
        const uint32_t h = edges[i];
        if (h / 3 == r0)
          hr = h;
        else if (h != h0)
          (tail(faces, h) == head(faces, h0) ? across : other) = h;
      }
      if (hr != kNoId && across != kNoId && other != kNoId &&
          tail(faces, other) == head(faces, hr)) {
        twin[h0] = across;
        twin[across] = h0;
        twin[hr] = other;
        twin[other] = hr;
        sides_paired = true;
      }
    }
  }

  for (const auto& [key, f] : by_vertices) {
    const uint32_t r = reverse_of(f);
    if (r == kNoId) continue;
    uint32_t partner[3];
    bool laid_on = true;
    for (uint32_t k = 0; k < 3 && laid_on; ++k) {
      const uint32_t h = 3 * f + k, e = edge_at(h);
      laid_on = e != kNoId && offsets[e + 1] - offsets[e] == 3 && on_edge(e, r);
      if (!laid_on) break;
      for (uint32_t i = offsets[e]; i < offsets[e + 1]; ++i)
        if (edges[i] / 3 != f && edges[i] / 3 != r) partner[k] = edges[i];
      laid_on = tail(faces, partner[k]) == head(faces, h);
    }
    if (!laid_on) continue;
    for (uint32_t k = 0; k < 3; ++k) {
      twin[3 * f + k] = partner[k];
      twin[partner[k]] = 3 * f + k;
    }
  }
  return sides_paired;
}

// `sides_paired`: whether the sides of a double-sided surface were paired across an edge.
std::vector<uint32_t> pair_edges(const std::vector<Triangle>& faces, size_t vertices,
                                 const std::vector<uint8_t>& sides_apart,
                                 uint64_t* nonmanifold_edges, bool* sides_paired,
                                 ChunkedLoops& loops) {
  const size_t halfedges = 3 * faces.size();
  std::vector<uint32_t> twin = filled_touched<uint32_t>(halfedges, kNoId, loops);
  // Each range of vertices groups the halfedges of its undirected edges: bucketed by the lower
  // end, holding (higher end << 32 | halfedge), each bucket sorted (ties by halfedge id). An
  // edge is its lower end's range's alone, so the ranges pair apart; their cut edges are
  // joined in vertex order.
  struct Cuts {
    std::vector<uint32_t> halfedges;
    std::vector<uint32_t> ends;  // per cut edge, the end of its halfedges in `halfedges`
  };
  std::vector<Cuts> cuts(loops.ranges(vertices));
  auto lower_end = [&](size_t h) {
    return std::min(tail(faces, uint32_t(h)), head(faces, uint32_t(h)));
  };
  const auto halfedges_of_range = items_of_ranges(loops, halfedges, vertices, lower_end);
  loops.run_indexed(vertices, [&](size_t range, size_t first, size_t last) {
    const RangeItems mine(halfedges_of_range, range, halfedges);
    std::vector<uint64_t> entries;
    std::vector<uint32_t> starts;
    bucket_by_vertex(
        mine.size(), last - first, [&](size_t i) { return VertexId(lower_end(mine[i]) - first); },
        [&](size_t i) {
          const uint32_t h = mine[i];
          return uint64_t(std::max(tail(faces, h), head(faces, h))) << 32 | h;
        },
        &entries, &starts);
    Cuts& cut = cuts[range];
    for (size_t v = 0; v < last - first; ++v) {
      const auto begin = entries.begin() + starts[v], end = entries.begin() + starts[v + 1];
      std::sort(begin, end);
      for (auto run = begin; run != end;) {
        auto run_end = run + 1;
        while (run_end != end && *run_end >> 32 == *run >> 32) ++run_end;
        const uint32_t h0 = uint32_t(run[0]), h1 = uint32_t(run_end[-1]);
        if (run_end - run == 2 && tail(faces, h0) == head(faces, h1)) {
          twin[h0] = h1;
          twin[h1] = h0;
        } else if (run_end - run >= 2) {  // cut: its faces stay unpaired
          for (auto h = run; h != run_end; ++h) cut.halfedges.push_back(uint32_t(*h));
          cut.ends.push_back(uint32_t(cut.halfedges.size()));
        }
        run = run_end;
      }
    }
  });
  std::vector<uint32_t> cut_halfedges, cut_offsets{0};  // the non-manifold edges' halfedges
  for (const Cuts& cut : cuts) {
    const auto before = uint32_t(cut_halfedges.size());
    cut_halfedges.insert(cut_halfedges.end(), cut.halfedges.begin(), cut.halfedges.end());
    for (uint32_t end : cut.ends) cut_offsets.push_back(before + end);
  }
  *nonmanifold_edges = cut_offsets.size() - 1;
  *sides_paired =
      pair_faces_beside_their_reverses(faces, cut_halfedges, cut_offsets, sides_apart, twin);
  return twin;
}

// ---------------------------------------------------------------------------------------
// Step 4b: group each vertex's corners into fans and give every fan but the first a copy of
// the vertex. Corner c = 3 * face + i sits at faces[face][i]; its outgoing halfedge is c
// itself and its incoming one is 3 * face + (i + 2) % 3.

void split_fans(const std::vector<uint32_t>& twin, RepairedMesh* out, ChunkedLoops& loops) {
  Mesh& mesh = out->mesh;
  std::vector<Triangle>& faces = mesh.faces;
  const size_t corners = 3 * faces.size();
  const size_t n = mesh.vertex_count();

  // Each range of vertices labels its corners' fans, walking corners in increasing order: a fan
  // is named by its lowest corner, where the walk meets it first, so that a vertex meets its
  // fan with the lowest face first. Crossing a corner's outgoing halfedge leads to the next
  // corner clockwise around the vertex; crossing its incoming halfedge, counter-clockwise. A
  // fan's corners are its vertex's, so the ranges label apart.
  std::vector<uint32_t> fan_of = filled_touched<uint32_t>(corners, kNoId, loops);
  std::vector<std::vector<std::pair<VertexId, uint32_t>>> extra_in(loops.ranges(n));
  auto vertex_of = [&](size_t c) { return faces[c / 3][c % 3]; };
  const auto corners_of_range = items_of_ranges(loops, corners, n, vertex_of);
  loops.run_indexed(n, [&](size_t range, size_t first, size_t last) {
    std::vector<uint8_t> vertex_has_fan(last - first, 0);
    const RangeItems mine(corners_of_range, range, corners);
    for (size_t j = 0; j < mine.size(); ++j) {
      const uint32_t c = mine[j];
      const VertexId v = vertex_of(c);
      if (fan_of[c] != kNoId) continue;
      auto label = [&](uint32_t corner) {
        // Cannot happen with twins that pair opposite halfedges: the walk would loop, or
        // leave the vertex.
        if (fan_of[corner] != kNoId || vertex_of(corner) != v)
          throw_internal("repair: corner walked twice");
        fan_of[corner] = c;
      };
      label(c);
      bool closed = false;
      for (uint32_t x = c;;) {  // clockwise until the boundary or back to c
        const uint32_t t = twin[x];
        if (t == kNoId) break;
        const uint32_t next = 3 * (t / 3) + (t % 3 + 1) % 3;
        if (next == c) {
          closed = true;
          break;
        }
        label(next);
        x = next;
      }
      for (uint32_t x = c; !closed;) {  // then counter-clockwise until the boundary
        const uint32_t t = twin[3 * (x / 3) + (x % 3 + 2) % 3];
        if (t == kNoId) break;
        label(t);
        x = t;
      }
      if (!vertex_has_fan[v - first]) {
        vertex_has_fan[v - first] = 1;
      } else {
        extra_in[range].emplace_back(v, c);
      }
    }
  });
  std::vector<std::pair<VertexId, uint32_t>> extra_fans;  // (vertex, fan)
  for (const auto& extra : extra_in)
    extra_fans.insert(extra_fans.end(), extra.begin(), extra.end());

  // Copies are numbered by original vertex, then by lowest face (the fan order above).
  std::sort(extra_fans.begin(), extra_fans.end());
  if (n + extra_fans.size() >= kNoId) {
    throw Error(ErrorCode::kResourceExhausted, "repair: too many vertex copies");
  }
  std::vector<VertexId> copy_of;  // per fan (its lowest corner): its copy, or kNoId
  if (!extra_fans.empty()) copy_of.assign(corners, kNoId);
  for (size_t k = 0; k < extra_fans.size(); ++k) {
    const auto [v, fan] = extra_fans[k];
    copy_of[fan] = VertexId(n + k);
    mesh.positions.push_back(mesh.positions[v]);
    out->input_vertex.push_back(out->input_vertex[v]);
    if (k == 0 || extra_fans[k - 1].first != v) ++out->report.nonmanifold_vertices;
  }
  out->report.vertex_copies_added = extra_fans.size();
  if (extra_fans.empty()) return;

  for (uint32_t c = 0; c < corners; ++c)
    if (copy_of[fan_of[c]] != kNoId) faces[c / 3][c % 3] = copy_of[fan_of[c]];

  // The corners now on a copy take copies of their wedges, one per (copy, wedge) pair.
  if (!mesh.layout.any()) return;
  std::vector<std::tuple<VertexId, WedgeId, uint32_t>> moved;  // (copy, old wedge, corner)
  for (uint32_t c = 0; c < corners; ++c) {
    if (faces[c / 3][c % 3] >= n)
      moved.emplace_back(faces[c / 3][c % 3], mesh.face_wedges[c / 3][c % 3], c);
  }
  std::sort(moved.begin(), moved.end());
  const size_t floats = size_t(mesh.layout.floats_per_wedge());
  if (mesh.wedge_count() + moved.size() >= kNoId) {
    throw Error(ErrorCode::kResourceExhausted, "repair: too many wedge copies");
  }
  WedgeId copy = kNoId;
  for (size_t k = 0; k < moved.size(); ++k) {
    const auto [vertex, wedge, c] = moved[k];
    if (k == 0 || std::get<0>(moved[k - 1]) != vertex || std::get<1>(moved[k - 1]) != wedge) {
      copy = WedgeId(mesh.wedge_count());
      mesh.wedge_vertex.push_back(vertex);
      float values[9];  // at most 3 + 2 + 4 floats; copied out before the vector grows
      std::copy_n(mesh.wedge(wedge), floats, values);
      mesh.wedge_values.insert(mesh.wedge_values.end(), values, values + floats);
      out->input_wedge.push_back(out->input_wedge[wedge]);
    }
    mesh.face_wedges[c / 3][c % 3] = copy;
  }
}

// Step 4. Pairing each side of a double-sided surface with itself can bring a side round to
// the other through a fold (two double-sided triangles on one edge), which leaves two faces
// on one halfedge after the split: then the edges of those faces keep their sides apart and
// the split is made again, at most a few times before every side is kept apart. Without such
// a pairing the split is a manifold by construction (this file's opening comment) and is made
// once, unchecked.
void split_keeping_sides_apart_where_needed(RepairedMesh* out, ChunkedLoops& loops) {
  constexpr int kTries = 8;
  std::vector<uint8_t> sides_apart;  // per halfedge; empty: none kept apart
  for (int attempt = 1;; ++attempt) {
    uint64_t nonmanifold_edges = 0;
    bool sides_paired = false;
    const std::vector<uint32_t> twin =
        pair_edges(out->mesh.faces, out->mesh.vertex_count(), sides_apart, &nonmanifold_edges,
                   &sides_paired, loops);
    out->report.nonmanifold_edges = nonmanifold_edges;
    if (!sides_paired) {
      split_fans(twin, out, loops);
      return;
    }
    RepairedMesh split = *out;
    split_fans(twin, &split, loops);
    const std::vector<FaceId> shared =
        faces_sharing_a_halfedge(split.mesh.faces, split.mesh.vertex_count());
    if (shared.empty()) {
      *out = std::move(split);
      return;
    }
    sides_apart.resize(3 * out->mesh.faces.size(), 0);
    if (attempt == kTries) std::fill(sides_apart.begin(), sides_apart.end(), 1);
    for (FaceId f : shared)
      for (uint32_t k = 0; k < 3; ++k) sides_apart[3 * f + k] = 1;
  }
}

}  // namespace

std::vector<FaceId> faces_sharing_a_halfedge(const std::vector<Triangle>& faces,
                                             size_t vertex_count) {
  OutgoingHalfedges outgoing = outgoing_halfedges(faces, vertex_count);
  using Halfedge = OutgoingHalfedges::Halfedge;
  std::vector<uint8_t> shares(faces.size(), 0);
  for (VertexId v = 0; v < vertex_count; ++v) {
    const std::span<Halfedge> around = outgoing.of(v);
    if (around.size() > 16) {  // a hub: sorted, so that a fan of any size costs n log n
      std::sort(around.begin(), around.end(),
                [](const Halfedge& x, const Halfedge& y) { return x.to < y.to; });
      for (size_t i = 0; i + 1 < around.size(); ++i)
        if (around[i].to == around[i + 1].to)
          shares[around[i].face] = shares[around[i + 1].face] = 1;
      continue;
    }
    for (size_t i = 0; i < around.size(); ++i)
      for (size_t j = i + 1; j < around.size(); ++j)
        if (around[i].to == around[j].to) shares[around[i].face] = shares[around[j].face] = 1;
  }
  std::vector<FaceId> shared;
  for (FaceId f = 0; f < faces.size(); ++f)
    if (shares[f]) shared.push_back(f);
  return shared;
}

RepairedMesh repair_mesh(const Mesh& input, const RepairOptions& options) {
  // 1. Refuse what cannot be repaired: nothing below has to check a value or an index.
  validate(input);

  // 2. Faces that are not triangles of a surface (degenerate) or that repeat an earlier
  // face go; zero-area faces stay (the simplifier removes them first) but are counted.
  ChunkedLoops one_thread;
  ChunkedLoops& loops = options.loops ? *options.loops : one_thread;
  FaceFilter filter = filter_faces(input.faces, input.vertex_count(), loops);
  RepairedMesh out;
  out.input_vertex_count = input.vertex_count();
  out.input_face_count = input.face_count();
  out.report.degenerate_faces_removed = filter.degenerate;
  out.report.duplicate_faces_removed = filter.duplicate;
  std::vector<uint64_t> zero_area(loops.ranges(filter.kept.size()), 0);
  loops.run_indexed(filter.kept.size(), [&](size_t range, size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      const Triangle& t = input.faces[filter.kept[j]];
      if (has_zero_area(input.positions[t[0]], input.positions[t[1]], input.positions[t[2]]))
        ++zero_area[range];
    }
  });
  for (uint64_t count : zero_area) out.report.zero_area_faces += count;

  // 3. Vertices no face uses go (unless asked to keep them), with their wedges.
  compact(input, filter.kept, options, &out, loops);

  // 4. Cut along the non-manifold edges (faces laid back to back on a surface are cut off it,
  // the surface kept joined; the two sides of a double-sided surface each kept joined), then
  // copy each vertex once per extra fan.
  split_keeping_sides_apart_where_needed(&out, loops);

  // 5. Neighbours on the surface become neighbours in memory.
  if (options.spatial_order) order_spatially(out, loops);
  return out;
}

}  // namespace parapm
