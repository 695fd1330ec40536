// EnergyPriority's state transfer for the parallel build (energy_priority.h, "The parallel
// build's state"): the points, curves and wedges of a job's part of the mesh exported from the
// master and imported into the job's module, and what the job changed given back. Kept apart
// from the metric itself (energy_priority.cpp), which prices and performs collapses.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "simplify/energy_priority.h"
#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm {

namespace {

// Whether point i continues the run of points of one face before it (a state lists each
// face's points together: each run fills its face's list, reserved once for the run).
bool continues_run(const std::vector<EnergyState::Point>& points, size_t i) {
  return i > 0 && points[i].face != kNoId && points[i].face == points[i - 1].face;
}

// Calls body(first, end) for each run [first, end) of `points` (a face's points, or one parked
// point), side by side in `loops`' chunks: a chunk takes the runs that begin in its range, so
// that each face's list is filled by one chunk, in the written order.
template <class Body>
void for_each_run(ChunkedLoops& loops, const std::vector<EnergyState::Point>& points,
                  const Body& body) {
  loops.run(points.size(), [&](size_t begin, size_t end) {
    size_t first = begin;
    while (first < end && continues_run(points, first)) ++first;
    while (first < end) {
      size_t run_end = first + 1;
      while (run_end < points.size() && continues_run(points, run_end)) ++run_end;
      body(first, run_end);
      first = run_end;
    }
  });
}

}  // namespace

std::vector<size_t> EnergyPriority::first_points(const std::vector<FaceId>& faces,
                                                 const std::vector<VertexId>& vertices,
                                                 size_t& points) const {
  std::vector<size_t> first(faces.size() + 1);
  points = 0;
  for (size_t i = 0; i < faces.size(); ++i) {
    first[i] = points;
    points += face_points_[faces[i]].size();
  }
  first[faces.size()] = points;
  for (const VertexId v : vertices) points += parked_point_[v] != kNoPoint ? 1 : 0;
  return first;
}

void EnergyPriority::export_state(const std::vector<FaceId>& faces,
                                  const std::vector<VertexId>& vertices,
                                  const std::vector<WedgeId>& wedges, const IdMaps& maps,
                                  bool to_local, EnergyState& out, ChunkedLoops& loops,
                                  std::vector<double>* drifts) const {
  const IdTranslation to_face{maps.face, to_local}, to_vertex{maps.vertex, to_local};
  const int floats = scalar_.enabled() ? scalar_.floats() : 0;
  const bool values = floats && to_local;
  // A job's returned state (to global ids) leaves out what never changes (EnergyState::positions).
  out.positions = to_local;
  // A face's drift goes into its points' distances: the state holds bounds, and no drift
  // (unless `drifts` takes the drifts apart: then the stored distances).
  auto write_point = [&](size_t at, const FacePoint& p, FaceId face, VertexId vertex,
                         double distance_sq) {
    const uint32_t id = p.id;
    EnergyState::Point& written = out.points[at];
    written.id = point_id_.empty() ? id : point_id_[id];
    written.face = face;
    written.vertex = vertex;
    if (to_local) written.position = p.position;
    written.distance_sq = distance_sq;
    if (floats) written.residual = scalar_.residual(id);
    if (values)
      std::copy_n(scalar_.point_values(id), floats,
                  out.point_values.begin() + ptrdiff_t(at * size_t(floats)));
  };
  // (the faces written side by side; sized once, exactly)
  size_t points = 0;
  const std::vector<size_t> first_point = first_points(faces, vertices, points);
  resize_touched(out.points, points, loops);
  if (values) resize_touched(out.point_values, points * size_t(floats), loops);
  resize_touched(out.faces, faces.size(), loops);
  if (drifts) resize_touched(*drifts, faces.size(), loops);
  // (Each id translated near its own position in the list: exact when the list is the map
  // itself, a job's export_local.)
  loops.run(faces.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const FaceId f = faces[i];
      const FaceId written = to_face.near(f, i);
      out.faces[i] = written;
      size_t at = first_point[i];
      if (drifts) (*drifts)[i] = drift_[f];
      for (const FacePoint& p : face_points_[f])
        write_point(at++, p, written, kNoId, drifts ? p.distance_sq : bounded_distance_sq(f, p));
    }
  });
  out.vertices.reserve(vertices.size());
  size_t at = first_point[faces.size()];
  for (size_t i = 0; i < vertices.size(); ++i) {
    const VertexId v = vertices[i];
    const VertexId written = to_vertex.near(v, i);
    out.vertices.push_back(written);
    if (parked_point_[v] != kNoPoint)
      write_point(at++, parked(parked_point_[v]), kNoId, written, 0.0);
  }
  curves_.export_state(vertices, to_vertex, out);
  if (floats) scalar_.export_wedges(wedges, IdTranslation{maps.wedge, to_local}, out);
}

EnergyState EnergyPriority::export_local(const IdMaps& maps, ChunkedLoops& loops) const {
  EnergyState state;
  const std::vector<WedgeId> none;
  export_state(*maps.face, *maps.vertex, maps.wedge ? *maps.wedge : none, maps, true, state, loops);
  return state;
}

EnergyState EnergyPriority::export_with_drifts(const IdMaps& maps, ChunkedLoops& loops,
                                               std::vector<double>& drifts) const {
  EnergyState state;
  const std::vector<WedgeId> none;
  export_state(*maps.face, *maps.vertex, maps.wedge ? *maps.wedge : none, maps, true, state, loops,
               &drifts);
  return state;
}

void EnergyPriority::set_drifts(const std::vector<double>& drifts) {
  if (drifts.size() != drift_.size())
    throw_invalid("energy state: " + std::to_string(drifts.size()) + " drifts for " +
                  std::to_string(drift_.size()) + " faces");
  for (double d : drifts)
    if (!(d >= 0) || !std::isfinite(d)) throw_invalid("energy state: a face's drift is not finite");
  drift_ = drifts;
}

EnergyState EnergyPriority::export_global(const CollapseMesh& mesh, const IdMaps& maps,
                                          const std::vector<uint8_t>& changed,
                                          ChunkedLoops& loops) const {
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
  export_state(faces, vertices, wedges, maps, false, state, loops);
  return state;
}

void EnergyPriority::import_local(const CollapseMesh& mesh, const EnergyState& state,
                                  ChunkedLoops& loops) {
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
  const std::vector<EnergyState::Point>& points = state.points;
  const size_t n = points.size();
  resize_touched(positions_, n, loops);
  resize_touched(point_id_, n, loops);
  reset_point_lists(mesh, loops);
  // Each face's points come as one run (the state lists them grouped by face), which fills
  // its list in the written order; the runs side by side in `loops`' chunks, each chunk taking
  // the runs that start in its range. A face named by two runs, or a vertex parked at twice,
  // is refused: two chunks would fill one list.
  std::vector<std::atomic<uint8_t>> face_taken(mesh.face_capacity());
  std::vector<std::atomic<uint8_t>> vertex_taken(mesh.vertex_capacity());
  for_each_run(loops, points, [&](size_t first, size_t end) {
    const EnergyState::Point& p = points[first];
    if (p.face != kNoId) {
      if (p.face >= mesh.face_capacity()) throw_invalid("energy state: face out of range");
      if (face_taken[p.face].exchange(1))
        throw_invalid("energy state: the points of face " + std::to_string(p.face) +
                      " are not listed together");
      face_points_[p.face].reserve(end - first);
    } else {
      if (p.vertex >= mesh.vertex_capacity()) throw_invalid("energy state: vertex out of range");
      if (vertex_taken[p.vertex].exchange(1))
        throw_invalid("energy state: two points parked at vertex " + std::to_string(p.vertex));
      parked_point_[p.vertex] = uint32_t(first);
    }
    for (size_t i = first; i < end; ++i) {
      point_id_[i] = points[i].id;
      positions_[i] = points[i].position;
      if (p.face != kNoId)
        face_points_[p.face].push_back({points[i].position, points[i].distance_sq, uint32_t(i)});
    }
  });
}

void EnergyPriority::import_from(const EnergyPriority& master, const CollapseMesh& mesh,
                                 const IdMaps& maps, bool drifts, ChunkedLoops& loops) {
  if (master.carries_attributes() || (mesh.has_wedges() && attributes_.layout.any()))
    throw_internal("EnergyPriority::import_from: a module with attributes");
  const std::vector<FaceId>& faces = *maps.face;
  const std::vector<VertexId>& vertices = *maps.vertex;
  const IdTranslation to_face{maps.face, true}, to_vertex{maps.vertex, true};
  // The state without its points: the vertices' curves, which import_local reads from it.
  EnergyState curves;
  curves.vertices.reserve(vertices.size());
  for (size_t i = 0; i < vertices.size(); ++i)
    curves.vertices.push_back(to_vertex.near(vertices[i], i));
  master.curves_.export_state(vertices, to_vertex, curves);
  const double diagonal = diagonal_of(mesh);
  topology_price_ = topology_price(diagonal);
  scalar_.import_local(AttributeLayout{}, options_.attribute_weight * diagonal, curves);
  if (options_.discontinuities) {
    curves_.import_local(mesh, curves);
  } else {
    curves_ = SharpCurves{};
    curves_.initialize_empty(mesh);
  }
  // The points as export_local lists them: each face's in its order, then the parked ones.
  size_t points = 0;
  const std::vector<size_t> first_point = master.first_points(faces, vertices, points);
  resize_touched(positions_, points, loops);
  resize_touched(point_id_, points, loops);
  reset_point_lists(mesh, loops);
  auto master_id = [&](uint32_t id) {
    return master.point_id_.empty() ? id : master.point_id_[id];
  };
  loops.run(faces.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const FaceId f = faces[i];
      const FaceId local = to_face.near(f, i);
      const std::vector<FacePoint>& from = master.face_points_[f];
      std::vector<FacePoint>& list = face_points_[local];
      list.reserve(from.size());
      size_t at = first_point[i];
      for (const FacePoint& p : from) {
        point_id_[at] = master_id(p.id);
        positions_[at] = p.position;
        list.push_back(
            {p.position, drifts ? p.distance_sq : master.bounded_distance_sq(f, p), uint32_t(at)});
        ++at;
      }
      if (drifts) drift_[local] = master.drift_[f];
    }
  });
  size_t at = first_point[faces.size()];
  for (size_t i = 0; i < vertices.size(); ++i) {
    const uint32_t id = master.parked_point_[vertices[i]];
    if (id == kNoPoint) continue;
    point_id_[at] = master_id(id);
    positions_[at] = master.positions_[id];
    parked_point_[curves.vertices[i]] = uint32_t(at++);
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
                                                          const GlobalOwners& owners,
                                                          ChunkedLoops& loops) const {
  if (subset >= 512) throw_internal("energy state import: subset " + std::to_string(subset));
  const uint32_t tag = (import_generation_ << 10) | (subset << 1), given = tag | 1;
  auto mark = [](std::vector<uint32_t>& tags, uint32_t i) {
    return std::atomic_ref<uint32_t>(tags[i]);
  };
  auto fail = [](const std::string& problem) { throw_invalid("energy state: " + problem); };
  auto face_ours = [&](FaceId f) {
    return f < face_points_.size() && (!owners.face_subset || (*owners.face_subset)[f] == subset);
  };
  auto vertex_ours = [&](VertexId v) {
    return v < parked_point_.size() &&
           (!owners.vertex_subset || (*owners.vertex_subset)[v] == subset);
  };
  // Each listed face and vertex checked and marked once (in range, the subset's, not listed
  // before), and the points on it marked as the state's to name.
  auto mark_listed = [&](const std::vector<uint32_t>& listed, const char* kind, size_t count,
                         const auto& ours, std::vector<uint32_t>& tags, const auto& points_on) {
    loops.run(listed.size(), [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        const uint32_t id = listed[i];
        const char* why = id >= count ? " out of range"
                          : !ours(id) ? " is another subset's"
                          : mark(tags, id).exchange(tag, std::memory_order_relaxed) == tag
                              ? " listed twice"
                              : nullptr;
        if (why) fail(kind + std::to_string(id) + why);
        points_on(id, [&](uint32_t point) {
          mark(point_tag_, point).store(tag, std::memory_order_relaxed);
        });
      }
    });
  };
  mark_listed(state.faces, "face ", face_points_.size(), face_ours, face_tag_,
              [&](FaceId f, const auto& mark_point) {
                for (const FacePoint& p : face_points_[f]) mark_point(p.id);
              });
  mark_listed(state.vertices, "vertex ", parked_point_.size(), vertex_ours, vertex_tag_,
              [&](VertexId v, const auto& mark_point) {
                if (parked_point_[v] != kNoPoint) mark_point(parked_point_[v]);
              });
  // Each point once; a face's points in one run, which begins by marking the face given, a
  // parked point by marking its vertex given. A chunk checks the runs that begin in its range.
  const std::vector<EnergyState::Point>& points = state.points;
  for_each_run(loops, points, [&](size_t first, size_t end) {
    for (size_t i = first; i < end; ++i) {
      const EnergyState::Point& p = points[i];
      const char* why = nullptr;
      uint32_t was = tag;
      if (p.id >= positions_.size()) {
        why = " out of range";
      } else if (!mark(point_tag_, p.id)
                      .compare_exchange_strong(was, given, std::memory_order_relaxed)) {
        why = was == given ? " given twice" : " is not the job's";
      } else if (i > first) {
        // (its face checked with the run's first point)
      } else if (p.face != kNoId ? !face_ours(p.face) : !vertex_ours(p.vertex)) {
        why = " is on a face or vertex the state does not list";
      } else if (uint32_t listed = tag;
                 !mark(p.face != kNoId ? face_tag_ : vertex_tag_,
                       p.face != kNoId ? p.face : p.vertex)
                      .compare_exchange_strong(listed, given, std::memory_order_relaxed)) {
        why = listed != given   ? " is on a face or vertex the state does not list"
              : p.face != kNoId ? " is on a face whose points are not listed together"
                                : " is parked at a vertex with another point parked there";
      }
      if (why) fail("point " + std::to_string(p.id) + why);
    }
  });
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

void EnergyPriority::apply_global(const EnergyState& state, const GlobalImport& import,
                                  ChunkedLoops& loops) {
  loops.run(state.faces.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const FaceId f = state.faces[i];
      face_points_[f].clear();
      evaluator_.forget(f);
      drift_[f] = 0;
    }
  });
  for (VertexId v : state.vertices) parked_point_[v] = kNoPoint;
  // The faces keep the written order: each run of a face's points (check_global: one per
  // face) fills its list, in the chunk where it begins.
  const std::vector<EnergyState::Point>& points = state.points;
  for_each_run(loops, points, [&](size_t first, size_t end) {
    if (points[first].face != kNoId) {
      std::vector<FacePoint>& list = face_points_[points[first].face];
      list.reserve(list.size() + (end - first));
    }
    for (size_t i = first; i < end; ++i) {
      const EnergyState::Point& p = points[i];
      if (p.face != kNoId) {
        face_points_[p.face].push_back({positions_[p.id], p.distance_sq, p.id});
      } else {
        parked_point_[p.vertex] = p.id;
      }
      if (scalar_.enabled()) scalar_.set_residual(p.id, p.residual);
    }
  });
  // A face left without points (most were removed by the job) gives its list's memory back.
  loops.run(state.faces.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i)
      if (face_points_[state.faces[i]].empty()) face_points_[state.faces[i]].shrink_to_fit();
  });
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
