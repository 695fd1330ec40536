#include "simplify/collapse_mesh.h"

#include <algorithm>
#include <atomic>

#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm {

CollapseMesh::CollapseMesh(const Mesh& mesh) {
  ChunkedLoops plain;
  build(mesh, plain);
}

CollapseMesh::CollapseMesh(const Mesh& mesh, ChunkedLoops& loops) { build(mesh, loops); }

void CollapseMesh::build(const Mesh& mesh, ChunkedLoops& loops) {
  // (each large array's pages touched in chunks first: fresh_pages.h)
  const size_t vertices = mesh.positions.size();
  copy_touched(positions_, mesh.positions, loops);
  copy_touched(faces_, mesh.faces, loops);
  copy_touched(corner_wedges_, mesh.face_wedges, loops);
  assign_touched<uint8_t>(face_alive_, mesh.faces.size(), 1, loops);
  assign_touched<uint8_t>(vertex_alive_, vertices, 0, loops);
  faces_of_.resize(vertices, loops);
  assign_touched<uint8_t>(boundary_, vertices, 0, loops);
  assign_touched<uint64_t>(imbalance_, vertices, 0, loops);
  assign_touched<uint32_t>(star_version_, vertices, 0, loops);
  identity_ = Identity();
  live_faces_ = mesh.faces.size();
  assign_touched<uint32_t>(mark_, vertices, 0, loops);
  // Each range of vertices lists its own corners' faces, in face order whatever the chunking.
  auto vertex_of = [&](size_t corner) { return faces_[corner / 3][corner % 3]; };
  const auto corners_of_range =
      items_of_ranges(loops, 3 * faces_.size(), positions_.size(), vertex_of);
  loops.run_indexed(positions_.size(), [&](size_t range, size_t begin, size_t end) {
    const RangeItems corners(corners_of_range, range, 3 * faces_.size());
    std::vector<uint32_t> valence(end - begin, 0);
    for (size_t j = 0; j < corners.size(); ++j) ++valence[vertex_of(corners[j]) - begin];
    for (size_t v = begin; v < end; ++v) faces_of_.reserve_list(VertexId(v), valence[v - begin]);
    for (size_t j = 0; j < corners.size(); ++j)
      faces_of_.push(vertex_of(corners[j]), FaceId(corners[j] / 3));
    for (size_t v = begin; v < end; ++v) {
      if (faces_of(VertexId(v)).empty()) continue;
      vertex_alive_[v] = 1;
      imbalance_[v] = fan_imbalance(VertexId(v));
      boundary_[v] = imbalance_[v] != 0;
    }
  });
  live_vertices_ = size_t(std::count(vertex_alive_.begin(), vertex_alive_.end(), 1));
}

void CollapseMesh::order_faces_of(VertexId v, std::span<const FaceId> faces) {
  if (faces.size() != faces_of(v).size())
    throw_internal("order_faces_of: another count of faces than the vertex has");
  faces_of_.assign(v, faces);
}

EdgeFaces CollapseMesh::edge_faces(VertexId a, VertexId b) const {
  // Read off the shorter face list (a fan's hub holds hundreds).
  const bool from_a = faces_of(a).size() <= faces_of(b).size();
  const VertexId from = from_a ? a : b, to = from_a ? b : a;
  EdgeFaces result;
  FaceId& onward = from_a ? result.left : result.right;  // the face holding from -> to
  VertexId& onward_apex = from_a ? result.left_apex : result.right_apex;
  FaceId& back = from_a ? result.right : result.left;  // the face holding to -> from
  VertexId& back_apex = from_a ? result.right_apex : result.left_apex;
  // (selected, not branched to: which faces of the fan hold the edge follows no pattern)
  for (FaceId f : faces_of(from)) {
    const Triangle& t = faces_[f];
    const int i = corner_of(t, from);
    const VertexId next = t[(i + 1) % 3];
    const VertexId prev = t[(i + 2) % 3];
    const bool holds_onward = next == to;
    const bool holds_back = (prev == to) & !holds_onward;
    onward = holds_onward ? f : onward;
    onward_apex = holds_onward ? prev : onward_apex;
    back = holds_back ? f : back;
    back_apex = holds_back ? next : back_apex;
  }
  return result;
}

std::vector<FaceId> CollapseMesh::twin_faces() const {
  ChunkedLoops plain;
  return twin_faces(plain);
}

std::vector<FaceId> CollapseMesh::twin_faces(ChunkedLoops& loops) const {
  std::vector<FaceId> twin = filled_touched<FaceId>(3 * faces_.size(), kNoId, loops);
  // A vertex a writes the slots of a's corners only: ranges of vertices write apart.
  loops.run(vertex_capacity(), [&](size_t begin, size_t end) {
    std::vector<std::pair<VertexId, FaceId>> fan;  // (the vertex before a, the face) around a
    for (size_t a = begin; a < end; ++a) {
      fan.clear();
      for (FaceId f : faces_of(VertexId(a)))
        fan.emplace_back(faces_[f][(corner_of(faces_[f], VertexId(a)) + 2) % 3], f);
      for (FaceId f : faces_of(VertexId(a))) {
        const int i = corner_of(faces_[f], VertexId(a));
        const VertexId next = faces_[f][(i + 1) % 3];
        // The face holding next -> a: next comes before a there (the last one, as edge_faces).
        FaceId across = kNoId;
        for (const auto& [before, g] : fan) across = before == next ? g : across;
        twin[3 * size_t(f) + size_t(i)] = across;
      }
    }
  });
  return twin;
}

uint32_t CollapseMesh::next_stamp() const {
  if (++stamp_ == 0) {  // wrapped: old marks could collide with new stamps
    std::fill(mark_.begin(), mark_.end(), 0);
    stamp_ = 1;
  }
  return stamp_;
}

void CollapseMesh::neighbors(VertexId v, std::vector<VertexId>& out) const {
  const std::span<const FaceId> fan = faces_of(v);
  out.resize(3 * fan.size());
  const uint32_t seen = next_stamp();
  mark_[v] = seen;
  // Each corner written, kept when not seen before: no branch on whether a neighbour repeats
  // (half of them do, in no pattern).
  size_t count = 0;
  for (FaceId f : fan)
    for (VertexId n : faces_[f]) {
      out[count] = n;
      count += mark_[n] != seen;
      mark_[n] = seen;
    }
  out.resize(count);
}

// A vertex is on the boundary when one of its edges has a face on one side only. On a
// manifold the faces (v, a, b) around v form a fan: closed, every "next" corner a is also the
// "previous" corner b of the face before it, so the two id sums agree; open (a chain from
// a_first to a_last != a_first), they differ by a_first - a_last. O(valence).
uint64_t CollapseMesh::fan_imbalance(VertexId v) const {
  uint64_t next_sum = 0, prev_sum = 0;
  for (FaceId f : faces_of(v)) {
    const Triangle& t = faces_[f];
    const int i = corner_of(t, v);
    next_sum += t[(i + 1) % 3];
    prev_sum += t[(i + 2) % 3];
  }
  return next_sum - prev_sum;
}

void CollapseMesh::remove_face_from(VertexId v, FaceId f) {
  if (!faces_of_.remove_swapping_last(v, f))
    throw_internal("collapse: face missing from its vertex's list");
}

void CollapseMesh::count_removed(const RemovedCounts& removed) {
  live_faces_ -= removed.faces;
  live_vertices_ -= removed.vertices;
}

void CollapseMesh::collapse(VertexId vs, VertexId vt, const Vec3& position,
                            const EdgeFaces& removed, RemovedCounts* counted) {
  RemovedCounts here;
  for (FaceId f : {removed.left, removed.right}) {
    if (f == kNoId) continue;
    face_alive_[f] = 0;
    ++here.faces;
    const Triangle& t = faces_[f];
    for (int k = 0; k < 3; ++k) {
      remove_face_from(t[k], f);
      imbalance_[t[k]] -= uint64_t(t[(k + 1) % 3]) - t[(k + 2) % 3];
    }
  }
  // vt's corners become vs's, with what they add to the sums; the corner after vt in a face
  // has vs before it now, the corner before vt has vs after it.
  const uint64_t step = uint64_t(vs) - vt;
  for (FaceId f : faces_of(vt)) {
    Triangle& t = faces_[f];
    const int k = corner_of(t, vt);
    t[k] = vs;
    imbalance_[t[(k + 1) % 3]] -= step;
    imbalance_[t[(k + 2) % 3]] += step;
    faces_of_.push(vs, f);
  }
  imbalance_[vs] += imbalance_[vt];
  imbalance_[vt] = 0;
  faces_of_.release(vt);
  vertex_alive_[vt] = 0;
  ++here.vertices;
  // The collapse of a component's last triangle (ComponentMinimum, when components may vanish)
  // leaves vs and the apex without faces: they stay in the mesh (the split that brings the
  // triangle back needs them) but are no longer alive, as alive means having faces.
  for (VertexId v : {vs, removed.left_apex, removed.right_apex})
    if (v != kNoId && vertex_alive_[v] && faces_of(v).empty()) {
      vertex_alive_[v] = 0;
      ++here.vertices;
    }
  if (counted) {
    counted->faces += here.faces;
    counted->vertices += here.vertices;
  } else {
    count_removed(here);
  }
  positions_[vs] = position;
  boundary_[vt] = 0;
  // A legal collapse changes the boundary status of vs and of the apexes only.
  for (VertexId v : {vs, removed.left_apex, removed.right_apex})
    if (v != kNoId) boundary_[v] = imbalance_[v] != 0;
  // Every vertex whose star lost a face or holds vs: vs, vt, the apexes (an apex may keep no
  // face with vs) and the corners of vs's faces.
  for (VertexId v : {vs, vt, removed.left_apex, removed.right_apex})
    if (v != kNoId) ++star_version_[v];
  for (FaceId f : faces_of(vs))
    for (VertexId v : faces_[f]) star_version_[v] += v != vs;  // (vs's, above)
}

uint64_t CollapseMesh::Identity::next() {
  static std::atomic<uint64_t> drawn{0};
  return ++drawn;
}

uint32_t connected_components(const CollapseMesh& mesh, std::vector<uint32_t>& component) {
  const size_t n = mesh.vertex_capacity();
  std::vector<VertexId> parent(n);
  for (VertexId v = 0; v < n; ++v) parent[v] = v;
  auto find = [&](VertexId v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!mesh.face_alive(f)) continue;
    const Triangle& t = mesh.face(f);
    for (int k = 1; k < 3; ++k) {
      const VertexId a = find(t[0]), b = find(t[k]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  component.assign(n, kNoId);
  std::vector<uint32_t> index_of_root(n, kNoId);
  uint32_t count = 0;
  for (VertexId v = 0; v < n; ++v) {
    if (!mesh.vertex_alive(v)) continue;
    const VertexId root = find(v);
    if (index_of_root[root] == kNoId) index_of_root[root] = count++;
    component[v] = index_of_root[root];
  }
  return count;
}

}  // namespace parapm
