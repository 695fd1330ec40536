// The vertex split on a mesh with vertex -> face adjacency (fan_mesh.h). The fan rule, in
// the mesh before the split, with "(vs, a, b)" a face of vs rotated to start at vs:
//  - the next face counter-clockwise after (vs, a, b) is the face holding vs->b, the previous
//    one (clockwise) is the face holding a->vs;
//  - with vr present: start at the face holding vs->vr and turn counter-clockwise until the
//    face holding vl->vs has been taken, or until there is no next face (a boundary);
//  - with vl present and either vr absent or that walk stopped at a boundary: start at the
//    face holding vl->vs and turn clockwise until there is no previous face;
//  - a starting face that does not exist contributes nothing (the new face fl or fr then
//    lies on a boundary of the fine mesh);
//  - a vs without faces has an empty fan; vl and vr then have no faces either, and fl and fr
//    make a new component (the collapse of a component's last faces, undone).
// Why both ends: in the fine mesh the faces of vt other than fl and fr run counter-clockwise
// from fr to fl; when vt is a boundary vertex that run is cut in two by the boundary, and in
// the coarse mesh the two pieces hang off the face holding vs->vr and the face holding vl->vs.
#include "pm/fan_mesh.h"

#include <algorithm>
#include <string>

#include "util/error.h"

namespace parapm {

namespace {
std::string str(uint64_t value) { return std::to_string(value); }

int corner_of(const Triangle& t, VertexId v) { return t[0] == v ? 0 : (t[1] == v ? 1 : 2); }
}  // namespace

FanMesh::FanMesh(const Mesh& base, bool attributes)
    : positions_(base.positions), faces_(base.faces), attributes_(attributes) {
  const size_t n = positions_.size();
  if (attributes_) {
    if (base.face_wedges.size() != faces_.size())
      throw_invalid("base mesh: corner wedges missing for some faces");
    face_wedges_ = base.face_wedges;
  }
  for (FaceId f = 0; f < faces_.size(); ++f) {
    const Triangle& t = faces_[f];
    for (VertexId v : t)
      if (v >= n)
        throw_invalid("base face " + str(f) + " names vertex " + str(v) + " of " + str(n));
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
      throw_invalid("base face " + str(f) + " is degenerate");
  }
  vertex_faces_.resize(n);
  for (FaceId f = 0; f < faces_.size(); ++f)
    for (VertexId v : faces_[f]) vertex_faces_.push(v, f);
}

void FanMesh::ensure_vertex(VertexId v) {
  if (v < positions_.size()) return;
  positions_.resize(size_t(v) + 1, Vec3{0, 0, 0});
  vertex_faces_.resize(size_t(v) + 1);
}

void FanMesh::prefetch_vertex(VertexId v) const {
  if (v >= positions_.size()) return;
  vertex_faces_.prefetch(v);
  __builtin_prefetch(&positions_[v]);
}

void FanMesh::prefetch_faces_of(VertexId v) const {
  if (v >= positions_.size()) return;
  for (FaceId f : vertex_faces_.of(v)) __builtin_prefetch(&faces_[f]);
}

void FanMesh::reserve(size_t vertices, size_t faces) {
  positions_.reserve(vertices);
  vertex_faces_.reserve(vertices);
  faces_.reserve(faces);
  if (attributes_) face_wedges_.reserve(faces);
}

void FanMesh::pop_vertex() {
  if (positions_.empty() || !vertex_faces_.of(VertexId(positions_.size() - 1)).empty())
    throw_internal("FanMesh::pop_vertex: the last vertex still has faces");
  positions_.pop_back();
  vertex_faces_.pop_back();
}

uint32_t FanMesh::find_a(VertexId x) const {
  if (by_a_.empty()) {
    for (uint32_t i = 0; i < ring_.size(); ++i)
      if (ring_[i].a == x) return i;
    return kNone;
  }
  const auto it = std::lower_bound(by_a_.begin(), by_a_.end(), x,
                                   [&](uint32_t i, VertexId key) { return ring_[i].a < key; });
  return it != by_a_.end() && ring_[*it].a == x ? *it : kNone;
}

uint32_t FanMesh::find_b(VertexId x) const {
  if (by_b_.empty()) {
    for (uint32_t i = 0; i < ring_.size(); ++i)
      if (ring_[i].b == x) return i;
    return kNone;
  }
  const auto it = std::lower_bound(by_b_.begin(), by_b_.end(), x,
                                   [&](uint32_t i, VertexId key) { return ring_[i].b < key; });
  return it != by_b_.end() && ring_[*it].b == x ? *it : kNone;
}

std::string FanMesh::find_fan(const VertexSplit& s, std::vector<FaceId>& fan) {
  fan.clear();
  const VertexId vs = s.vs;
  if (vertex_faces_.of(vs).empty()) {
    // A component coming back: vs, vl and vr (when present) are faceless vertices, which the
    // split joins by fl and fr alone.
    for (VertexId side : {s.vl, s.vr})
      if (side != kNoId && !vertex_faces_.of(side).empty())
        return (side == s.vl ? "vl " : "vr ") + str(side) + " has faces but vs " + str(vs) +
               " has none";
    return {};
  }
  ring_.clear();
  for (FaceId f : vertex_faces_.of(vs)) {
    const Triangle& t = faces_[f];
    const int k = corner_of(t, vs);
    ring_.push_back({t[(k + 1) % 3], t[(k + 2) % 3], f});
  }
  by_a_.clear();
  by_b_.clear();
  if (ring_.size() > kSortedFanThreshold) {
    // Sorted by (key, position in the ring): the same face as the linear scan's first match.
    by_a_.resize(ring_.size());
    for (uint32_t i = 0; i < ring_.size(); ++i) by_a_[i] = i;
    by_b_ = by_a_;
    std::sort(by_a_.begin(), by_a_.end(), [&](uint32_t i, uint32_t j) {
      return ring_[i].a != ring_[j].a ? ring_[i].a < ring_[j].a : i < j;
    });
    std::sort(by_b_.begin(), by_b_.end(), [&](uint32_t i, uint32_t j) {
      return ring_[i].b != ring_[j].b ? ring_[i].b < ring_[j].b : i < j;
    });
  }
  for (VertexId side : {s.vl, s.vr})
    if (side != kNoId && find_a(side) == kNone && find_b(side) == kNone)
      return (side == s.vl ? "vl " : "vr ") + str(side) + " is not adjacent to vs " + str(vs);

  // Each face is taken at most once: meeting a face again means the walk went all the way
  // around vs without finding its end, which a valid split never does.
  visited_.assign(ring_.size(), 0);
  bool hit_boundary = true;
  if (s.has_fr()) {
    uint32_t i = find_a(s.vr);
    hit_boundary = i == kNone;
    while (i != kNone) {
      if (visited_[i])
        return s.has_fl() ? "turning around vs " + str(vs) + " from vr " + str(s.vr) +
                                " never reaches vl " + str(s.vl)
                          : "vs " + str(vs) + " has no boundary although vl is absent";
      visited_[i] = 1;
      fan.push_back(ring_[i].face);
      if (s.has_fl() && ring_[i].b == s.vl) break;  // the face holding vl->vs: the fan is whole
      i = find_a(ring_[i].b);
      if (i == kNone) hit_boundary = true;
    }
  }
  if (s.has_fl() && hit_boundary) {
    uint32_t i = find_b(s.vl);
    while (i != kNone) {
      if (visited_[i])
        return "turning clockwise around vs " + str(vs) + " from vl " + str(s.vl) +
               " never reaches a boundary";
      visited_[i] = 1;
      fan.push_back(ring_[i].face);
      i = find_b(ring_[i].a);
    }
  }
  return {};
}

void FanMesh::split(const VertexSplit& s, VertexId vt, std::span<const FaceId> fan) {
  if (!vertex_faces_.of(vt).empty()) throw_internal("FanMesh::split: vt already has faces");
  for (FaceId f : fan) {
    Triangle& t = faces_[f];
    t[corner_of(t, s.vs)] = vt;
  }
  // The fan leaves vs's list. Fans are short: a scan of the fan per face beats a per-face
  // mark (one more cache miss per face); long fans are searched sorted.
  if (fan.size() <= kSortedFanThreshold) {
    vertex_faces_.erase_if(s.vs, [&](FaceId f) {
      for (FaceId g : fan)
        if (g == f) return true;
      return false;
    });
  } else {
    scratch_.assign(fan.begin(), fan.end());
    std::sort(scratch_.begin(), scratch_.end());
    vertex_faces_.erase_if(
        s.vs, [&](FaceId f) { return std::binary_search(scratch_.begin(), scratch_.end(), f); });
  }
  vertex_faces_.assign(vt, fan);

  auto add_face = [&](const Triangle& t, int first_corner) {
    const FaceId f = FaceId(faces_.size());
    faces_.push_back(t);
    if (attributes_)
      face_wedges_.push_back({s.corner_wedges[first_corner], s.corner_wedges[first_corner + 1],
                              s.corner_wedges[first_corner + 2]});
    for (VertexId v : t) vertex_faces_.push(v, f);
  };
  if (s.has_fl()) add_face({s.vs, vt, s.vl}, 0);
  if (s.has_fr()) add_face({vt, s.vs, s.vr}, 3);
}

void FanMesh::unsplit(const VertexSplit& s, VertexId vt) {
  const size_t new_faces = size_t(s.new_faces());
  if (faces_.size() < new_faces) throw_internal("FanMesh::unsplit: faces missing");
  const FaceId first_new = FaceId(faces_.size() - new_faces);
  const auto is_new = [&](FaceId f) { return f >= first_new; };
  vertex_faces_.erase_if(s.vs, is_new);
  if (s.has_fl()) vertex_faces_.erase_if(s.vl, is_new);
  if (s.has_fr()) vertex_faces_.erase_if(s.vr, is_new);
  const std::span<const FaceId> of_vt = vertex_faces_.of(vt);
  scratch_.assign(of_vt.begin(), of_vt.end());
  for (FaceId f : scratch_) {
    if (f >= first_new) continue;
    Triangle& t = faces_[f];
    t[corner_of(t, vt)] = s.vs;
    vertex_faces_.push(s.vs, f);
  }
  vertex_faces_.clear(vt);
  faces_.resize(first_new);
  if (attributes_) face_wedges_.resize(first_new);
}

}  // namespace parapm
