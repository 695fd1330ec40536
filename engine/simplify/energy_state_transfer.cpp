// EnergyPriority's state transfer for the parallel build (energy_priority.h, "The parallel
// build's state"): the points, curves and wedges of a job's part of the mesh exported from the
// master and imported into the job's module, and what the job changed given back. Kept apart
// from the metric itself (energy_priority.cpp), which prices and performs collapses.
#include <algorithm>
#include <atomic>

#include "simplify/energy_priority.h"
#include "util/error.h"

namespace parapm {

namespace {

// Reserves each face's list for the run of `points` naming it (a state lists its points
// grouped by face): a list grown point by point would leave the blocks it outgrew behind.
// Faces out of range are left to the caller's checks.
void reserve_face_lists(const std::vector<EnergyState::Point>& points,
                        std::vector<std::vector<EnergyFacePoint>>& lists) {
  for (size_t i = 0, run = 0; i < points.size(); i += run) {
    const FaceId f = points[i].face;
    run = 1;
    while (i + run < points.size() && points[i + run].face == f) ++run;
    if (f < lists.size()) lists[f].reserve(lists[f].size() + run);
  }
}

}  // namespace

void EnergyPriority::export_state(const std::vector<FaceId>& faces,
                                  const std::vector<VertexId>& vertices,
                                  const std::vector<WedgeId>& wedges, const IdMaps& maps,
                                  bool to_local, EnergyState& out) const {
  const IdTranslation to_face{maps.face, to_local}, to_vertex{maps.vertex, to_local};
  const int floats = scalar_.enabled() ? scalar_.floats() : 0;
  // A job's returned state (to global ids) leaves out what never changes (EnergyState::positions).
  out.positions = to_local;
  // A face's drift goes into its points' distances: the state holds bounds, and no drift.
  auto add_point = [&](const FacePoint& p, FaceId face, VertexId vertex, double distance_sq) {
    const uint32_t id = p.id;
    out.points.push_back({point_id_.empty() ? id : point_id_[id], face, vertex,
                          to_local ? p.position : Vec3{}, distance_sq,
                          floats ? scalar_.residual(id) : 0.0});
    if (floats && to_local)
      out.point_values.insert(out.point_values.end(), scalar_.point_values(id),
                              scalar_.point_values(id) + floats);
  };
  // Sized once: grown by doubling, a state of a million points would leave up to twice its
  // size behind in freed blocks.
  size_t points = 0;
  for (const FaceId f : faces) points += face_points_[f].size();
  for (const VertexId v : vertices) points += parked_point_[v] != kNoPoint ? 1 : 0;
  out.points.reserve(points);
  if (floats && to_local) out.point_values.reserve(points * size_t(floats));
  out.faces.reserve(faces.size());
  out.vertices.reserve(vertices.size());
  // (Each id translated near its own position in the list: exact when the list is the map
  // itself, a job's export_local.)
  for (size_t i = 0; i < faces.size(); ++i) {
    const FaceId f = faces[i];
    const FaceId written = to_face.near(f, i);
    out.faces.push_back(written);
    for (const FacePoint& p : face_points_[f])
      add_point(p, written, kNoId, bounded_distance_sq(f, p));
  }
  for (size_t i = 0; i < vertices.size(); ++i) {
    const VertexId v = vertices[i];
    const VertexId written = to_vertex.near(v, i);
    out.vertices.push_back(written);
    if (parked_point_[v] != kNoPoint) add_point(parked(parked_point_[v]), kNoId, written, 0.0);
  }
  curves_.export_state(vertices, to_vertex, out);
  if (floats) scalar_.export_wedges(wedges, IdTranslation{maps.wedge, to_local}, out);
}

EnergyState EnergyPriority::export_local(const IdMaps& maps) const {
  EnergyState state;
  const std::vector<WedgeId> none;
  export_state(*maps.face, *maps.vertex, maps.wedge ? *maps.wedge : none, maps, true, state);
  return state;
}

EnergyState EnergyPriority::export_global(const CollapseMesh& mesh, const IdMaps& maps,
                                          const std::vector<uint8_t>& changed) const {
  // The faces around a changed vertex, alive or not: a collapse changes the points, corners and
  // drift of the faces around vs (its star, which stay around vs or the vertex vs later
  // collapses into) and removes two faces around vt. Their corners: a collapse renames vt in
  // its neighbours' sharp lists, and those neighbours stay neighbours of vs.
  std::vector<uint8_t> vertex_mark(changed.size(), 0);
  std::vector<FaceId> faces;
  std::vector<WedgeId> wedges;
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    const Triangle& t = mesh.face(f);
    if (!changed[t[0]] && !changed[t[1]] && !changed[t[2]]) continue;
    faces.push_back(f);
    for (int k = 0; k < 3; ++k) vertex_mark[t[k]] = 1;
    if (scalar_.enabled() && mesh.has_wedges())
      for (int k = 0; k < 3; ++k) wedges.push_back(mesh.corner_wedges(f)[k]);
  }
  std::vector<VertexId> vertices;
  for (VertexId v = 0; v < changed.size(); ++v)
    if (changed[v] || vertex_mark[v]) vertices.push_back(v);
  std::sort(wedges.begin(), wedges.end());
  wedges.erase(std::unique(wedges.begin(), wedges.end()), wedges.end());
  EnergyState state;
  export_state(faces, vertices, wedges, maps, false, state);
  return state;
}

void EnergyPriority::import_local(const CollapseMesh& mesh, const EnergyState& state) {
  if (!state.positions) throw_invalid("energy state: a job's state without its points' positions");
  const double diagonal = diagonal_of(mesh);
  topology_price_ = topology_price(diagonal);
  const bool scalar = mesh.has_wedges() && attributes_.layout.any();
  scalar_.import_local(scalar ? attributes_.layout : AttributeLayout{},
                       options_.attribute_weight * diagonal, state);
  if (options_.discontinuities) {
    curves_.import_local(mesh, state);
  } else {
    curves_ = SharpCurves{};
    curves_.initialize_empty(mesh);
  }
  const size_t n = state.points.size();
  positions_.resize(n);
  point_id_.resize(n);
  reset_point_lists(mesh);
  reserve_face_lists(state.points, face_points_);
  // The faces keep the written order.
  for (size_t i = 0; i < n; ++i) {
    const EnergyState::Point& p = state.points[i];
    const auto id = uint32_t(i);
    point_id_[i] = p.id;
    positions_[i] = p.position;
    if (p.face != kNoId) {
      if (p.face >= mesh.face_capacity()) throw_invalid("energy state: face out of range");
      face_points_[p.face].push_back({p.position, p.distance_sq, id});
    } else {
      if (p.vertex >= mesh.vertex_capacity()) throw_invalid("energy state: vertex out of range");
      parked_point_[p.vertex] = id;
    }
  }
}

void EnergyPriority::import_global(const EnergyState& state) {
  begin_global_imports();
  const GlobalImport import = check_global(state, 0, GlobalOwners{});
  apply_global(state, import);
  apply_global_wedges(state);
}

void EnergyPriority::begin_global_imports() {
  face_tag_.resize(face_points_.size(), 0);
  vertex_tag_.resize(parked_point_.size(), 0);
  point_tag_.resize(positions_.size(), 0);
  // A tag is (generation, subset, given): no mark is ever cleared.
  if (++import_generation_ >= (1u << 22)) {
    std::fill(face_tag_.begin(), face_tag_.end(), 0);
    std::fill(vertex_tag_.begin(), vertex_tag_.end(), 0);
    std::fill(point_tag_.begin(), point_tag_.end(), 0);
    import_generation_ = 1;
  }
}

// What a job gives back (possibly from a worker over the network) may only rearrange the
// points it was given: every point once, one that was on the state's faces or parked at its
// vertices, on one of those faces or parked at one of those vertices; and with owners, only
// faces and vertices of its subset. (Points never move: their positions are the master's.)
// Checked before the master changes anything. (A point may be missing: a collapse that leaves
// its vertex without faces drops its star's points, as the sequential build does.)
// Side by side for different subsets: a state's faces and vertices are checked to be its
// subset's before anything is marked, so each check marks only its own faces, vertices and
// the points on them; a point of another subset's (named by a dishonest state) is read while
// its check may be marking it, hence the relaxed atomics: the tag read is never this state's.
EnergyPriority::GlobalImport EnergyPriority::check_global(const EnergyState& state, uint32_t subset,
                                                          const GlobalOwners& owners) const {
  if (subset >= 512) throw_internal("energy state import: subset " + std::to_string(subset));
  const uint32_t tag = (import_generation_ << 10) | (subset << 1), given = tag | 1;
  auto point_tag = [&](uint32_t id) { return std::atomic_ref<uint32_t>(point_tag_[id]); };
  auto fail = [](const std::string& problem) { throw_invalid("energy state: " + problem); };
  auto face_ours = [&](FaceId f) {
    return f < face_points_.size() && (!owners.face_subset || (*owners.face_subset)[f] == subset);
  };
  auto vertex_ours = [&](VertexId v) {
    return v < parked_point_.size() &&
           (!owners.vertex_subset || (*owners.vertex_subset)[v] == subset);
  };
  for (FaceId f : state.faces) {
    if (f >= face_points_.size()) fail("face " + std::to_string(f) + " out of range");
    if (!face_ours(f)) fail("face " + std::to_string(f) + " is another subset's");
    face_tag_[f] = tag;
    for (const FacePoint& p : face_points_[f])
      point_tag(p.id).store(tag, std::memory_order_relaxed);
  }
  for (VertexId v : state.vertices) {
    if (v >= parked_point_.size()) fail("vertex " + std::to_string(v) + " out of range");
    if (!vertex_ours(v)) fail("vertex " + std::to_string(v) + " is another subset's");
    vertex_tag_[v] = tag;
    if (parked_point_[v] != kNoPoint)
      point_tag(parked_point_[v]).store(tag, std::memory_order_relaxed);
  }
  for (const EnergyState::Point& p : state.points) {
    const char* why = nullptr;
    if (p.id >= positions_.size()) {
      why = " out of range";
    } else if (const uint32_t t = point_tag(p.id).load(std::memory_order_relaxed); t != tag) {
      why = t == given ? " given twice" : " is not the job's";
    } else if (p.face != kNoId ? !face_ours(p.face) || face_tag_[p.face] != tag
                               : !vertex_ours(p.vertex) || vertex_tag_[p.vertex] != tag) {
      why = " is on a face or vertex the state does not list";
    }
    if (why) fail("point " + std::to_string(p.id) + why);
    point_tag(p.id).store(given, std::memory_order_relaxed);
  }
  if (options_.discontinuities) curves_.check_global(state);
  scalar_.check_global(state);
  // The curve samples it writes: those on an edge whose first end is the subset's now. A
  // sample on an edge between two subsets is listed by both (unchanged: no job moves a bound
  // vertex's samples), and written once.
  GlobalImport import;
  if (options_.discontinuities)  // (without, the curves are empty and take nothing)
    for (uint32_t i = 0; i < state.samples.size(); ++i)
      if (!owners.vertex_subset ||
          (*owners.vertex_subset)[curves_.sample_edge(state.samples[i].id).first] == subset)
        import.samples.push_back(i);
  return import;
}

void EnergyPriority::apply_global(const EnergyState& state, const GlobalImport& import) {
  for (FaceId f : state.faces) {
    face_points_[f].clear();
    evaluator_.forget(f);
    drift_[f] = 0;
  }
  for (VertexId v : state.vertices) parked_point_[v] = kNoPoint;
  reserve_face_lists(state.points, face_points_);
  // The faces keep the written order.
  for (const EnergyState::Point& p : state.points) {
    if (p.face != kNoId) {
      face_points_[p.face].push_back({positions_[p.id], p.distance_sq, p.id});
    } else {
      parked_point_[p.vertex] = p.id;
    }
    if (scalar_.enabled()) scalar_.set_residual(p.id, p.residual);
  }
  // A face left without points (most were removed by the job) gives its list's memory back.
  for (FaceId f : state.faces)
    if (face_points_[f].empty()) face_points_[f].shrink_to_fit();
  if (options_.discontinuities) curves_.import_global(state, &import.samples);
}

void EnergyPriority::apply_global_wedges(const EnergyState& state) { scalar_.import_global(state); }

std::vector<EnergyPriority::PointState> EnergyPriority::point_states() const {
  std::vector<PointState> states(positions_.size());
  for (size_t i = 0; i < positions_.size(); ++i) states[i].position = positions_[i];
  for (FaceId f = 0; f < face_points_.size(); ++f)
    for (const FacePoint& p : face_points_[f]) {
      states[p.id].face = f;
      states[p.id].distance_sq = bounded_distance_sq(f, p);
    }
  for (VertexId v = 0; v < parked_point_.size(); ++v)
    if (parked_point_[v] != kNoPoint) states[parked_point_[v]].parked = v;
  return states;
}

size_t EnergyPriority::held_point_count() const {
  size_t held = 0;
  for (const auto& list : face_points_) held += list.size();
  for (uint32_t id : parked_point_) held += id != kNoPoint ? 1 : 0;
  return held;
}

}  // namespace parapm
