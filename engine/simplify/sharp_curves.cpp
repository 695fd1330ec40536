#include "simplify/sharp_curves.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "simplify/back_to_back.h"
#include "simplify/point_projection.h"
#include "simplify/sample_thinning.h"
#include "util/error.h"
#include "util/union_find.h"

namespace parapm {
namespace {

bool contains(const std::vector<VertexId>& list, VertexId v) {
  return std::find(list.begin(), list.end(), v) != list.end();
}

void erase_value(std::vector<VertexId>& list, VertexId v) {
  list.erase(std::remove(list.begin(), list.end(), v), list.end());
}

// Drops the creases that are noise: a crease (a connected set of crease edges, not counting
// boundaries and seams) of fewer than min_crease_edges edges and shorter than
// long_crease_diagonals of the bounding-box diagonal. A scan's noise makes hundreds of such
// fragments (nefertiti-100k: 597 creases at 60 degrees, 535 of them of 1 to 3 edges), and a
// curve's ends never merge but through a penalised collapse, so each fragment would hold two
// or more vertices until every ordinary collapse is done: at 2% of the faces those vertices
// were most of the mesh (docs/decisions/notebook-2026-11.md, "The star's planes and its volume;
// noise creases").
void keep_long_creases(const CollapseMesh& mesh, const SharpEdgeOptions& options,
                       std::vector<std::pair<VertexId, VertexId>>& creases) {
  if (options.min_crease_edges <= 1 || creases.empty()) return;
  UnionFind sets(mesh.vertex_capacity());
  for (const auto& [a, b] : creases) sets.unite(a, b);
  struct Extent {
    uint32_t edges = 0;
    double length = 0;
  };
  std::unordered_map<VertexId, Extent> extent;
  for (const auto& [a, b] : creases) {
    Extent& e = extent[sets.find(a)];
    ++e.edges;
    e.length += length(sub(mesh.position(a), mesh.position(b)));
  }
  const double long_enough =
      options.long_crease_diagonals * bounding_box(mesh.positions()).diagonal();
  std::erase_if(creases, [&](const std::pair<VertexId, VertexId>& edge) {
    const Extent& e = extent[sets.find(edge.first)];
    return e.edges < options.min_crease_edges && e.length < long_enough;
  });
}

}  // namespace

std::vector<std::pair<VertexId, VertexId>> find_sharp_edges(const CollapseMesh& mesh,
                                                            const SharpEdgeOptions& options) {
  ChunkedLoops plain;
  return find_sharp_edges(mesh, options, plain);
}

std::vector<std::pair<VertexId, VertexId>> find_sharp_edges(const CollapseMesh& mesh,
                                                            const SharpEdgeOptions& options,
                                                            ChunkedLoops& loops) {
  using Edges = std::vector<std::pair<VertexId, VertexId>>;
  const double crease_cos = std::cos(options.crease_angle_degrees * M_PI / 180.0);
  const std::vector<FaceId> twin = mesh.twin_faces(loops);
  // Each range of faces finds its own edges; joined in face order, as one pass finds them.
  std::vector<std::pair<Edges, Edges>> found(loops.ranges(mesh.face_capacity()));
  loops.run_indexed(mesh.face_capacity(), [&](size_t range, size_t begin, size_t end) {
    auto& [edges, creases] = found[range];
    for (FaceId f = FaceId(begin); f < end; ++f) {
      if (!mesh.face_alive(f)) continue;
      const Triangle& t = mesh.face(f);
      for (int k = 0; k < 3; ++k) {
        const VertexId a = t[k], b = t[(k + 1) % 3];
        const FaceId g = twin[3 * size_t(f) + size_t(k)];
        if (g == kNoId) {
          if (options.boundaries) edges.emplace_back(std::min(a, b), std::max(a, b));
          continue;
        }
        if (a > b) continue;  // an interior edge is seen from both faces: take it once
        bool sharp = false;
        if (options.seams && mesh.has_wedges()) {
          const Triangle& u = mesh.face(g);
          sharp = mesh.corner_wedges(f)[k] != mesh.corner_wedges(g)[corner_of(u, a)] ||
                  mesh.corner_wedges(f)[(k + 1) % 3] != mesh.corner_wedges(g)[corner_of(u, b)];
        }
        if (sharp) {
          edges.emplace_back(a, b);
        } else {
          const Triangle& u = mesh.face(g);
          const Vec3 nf =
              triangle_normal(mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]));
          const Vec3 ng =
              triangle_normal(mesh.position(u[0]), mesh.position(u[1]), mesh.position(u[2]));
          const double lengths = length(nf) * length(ng);
          if (back_to_back(nf, ng)) {  // a double-sided sheet's rim: a border, kept as one
            if (options.boundaries) edges.emplace_back(a, b);
          } else if (lengths > 0 && dot(nf, ng) < crease_cos * lengths) {
            creases.emplace_back(a, b);
          }
        }
      }
    }
  });
  Edges edges, creases;
  for (const auto& [found_edges, found_creases] : found) {
    edges.insert(edges.end(), found_edges.begin(), found_edges.end());
    creases.insert(creases.end(), found_creases.begin(), found_creases.end());
  }
  keep_long_creases(mesh, options, creases);
  edges.insert(edges.end(), creases.begin(), creases.end());
  std::sort(edges.begin(), edges.end());
  return edges;
}

void SharpCurves::make_lists() {
  neighbors_.assign(vertex_capacity_, {});
  listed_at_.assign(vertex_capacity_, {});
}

void SharpCurves::add_sharp(VertexId a, VertexId b) {
  neighbors_[a].push_back(b);
  neighbors_[b].push_back(a);
}

void SharpCurves::initialize(const CollapseMesh& mesh, const SharpEdgeOptions& options) {
  ChunkedLoops plain;
  initialize(mesh, options, plain);
}

void SharpCurves::initialize(const CollapseMesh& mesh, const SharpEdgeOptions& options,
                             ChunkedLoops& loops) {
  samples_.clear();
  vertex_capacity_ = mesh.vertex_capacity();
  neighbors_.clear();
  listed_at_.clear();
  const auto edges = find_sharp_edges(mesh, options, loops);
  edge_count_ = edges.size();
  if (!edges.empty()) make_lists();
  for (const auto& [a, b] : edges) add_sharp(a, b);
  auto add_sample = [&](const Vec3& position, VertexId u, VertexId w) {
    const auto id = uint32_t(samples_.size());
    samples_.push_back({position, 0.0, u, w});
    listed_at_[u].push_back(id);
    listed_at_[w].push_back(id);
  };
  for (VertexId v = 0; v < neighbors_.size(); ++v)
    if (!neighbors_[v].empty()) add_sample(mesh.position(v), v, neighbors_[v][0]);
  for (const auto& [a, b] : edges)
    add_sample(scale(add(mesh.position(a), mesh.position(b)), 0.5), a, b);
  total_samples_ = samples_.size();
  sample_id_.clear();
}

void SharpCurves::initialize_empty(const CollapseMesh& mesh) {
  samples_.clear();
  vertex_capacity_ = mesh.vertex_capacity();
  neighbors_.clear();
  listed_at_.clear();
  edge_count_ = 0;
  total_samples_ = 0;
  sample_id_.clear();
}

bool SharpCurves::is_sharp(VertexId a, VertexId b) const { return contains(sharp_neighbors(a), b); }

bool SharpCurves::changes_topology(VertexId a, VertexId b) const {
  const auto& na = sharp_neighbors(a);
  const auto& nb = sharp_neighbors(b);
  if (na.empty() || nb.empty()) return false;
  if (!contains(na, b)) return true;
  for (VertexId x : na)
    if (x != b && contains(nb, x)) return true;
  return na.size() != 2 && nb.size() != 2;
}

void SharpCurves::gather(VertexId a, VertexId b, const CollapseMesh& mesh, size_t max_samples,
                         Gathered& out) const {
  std::vector<uint32_t>& gathered = out.samples;
  gathered.clear();
  out.weight = 1;
  out.ends.clear();
  out.end_positions.clear();
  if (samples_.empty()) return;
  gathered.insert(gathered.end(), listed_at(a).begin(), listed_at(a).end());
  for (uint32_t id : listed_at(b)) {
    const Sample& s = samples_[id];
    if (s.u != a && s.w != a) gathered.push_back(id);  // else listed at a too
  }
  if (max_samples > 0 && gathered.size() > max_samples) {
    const size_t n = gathered.size(), stride = (n + max_samples - 1) / max_samples;
    size_t kept = 0;
    for (size_t i = 0; i < n; ++i) {
      const uint32_t id = gathered[i];
      if (kept_when_thinned(sample_id_.empty() ? id : sample_id_[id], stride))
        gathered[kept++] = id;
    }
    if (kept > 0) {
      gathered.resize(kept);
      out.weight = double(n) / double(kept);
    }
  }
  for (VertexId end : {a, b})
    for (VertexId x : sharp_neighbors(end))
      if (x != a && x != b && !contains(out.ends, x)) {
        out.ends.push_back(x);
        out.end_positions.push_back(mesh.position(x));
      }
}

SharpCurves::Fit SharpCurves::project(const Gathered& gathered, const Vec3& v) const {
  Fit fit;
  for (uint32_t id : gathered.samples) {
    const Vec3& x = samples_[id].position;
    double best = std::numeric_limits<double>::infinity();
    double b0 = 1;
    Vec3 rest{};
    if (gathered.end_positions.empty()) {
      const Vec3 d = sub(x, v);
      best = dot(d, d);
    }
    for (const Vec3& e : gathered.end_positions) {
      const SegmentProjection p = project_on_segment(x, v, e);
      if (p.distance_sq < best) best = p.distance_sq, b0 = 1 - p.t, rest = scale(e, p.t);
    }
    fit.distance_sq += best;
    fit.max_distance_sq = std::max(fit.max_distance_sq, best);
    fit.a += b0 * b0;
    const Vec3 offset = sub(x, rest);
    fit.b = add(fit.b, scale(offset, b0));
    fit.c += dot(offset, offset);
  }
  if (gathered.weight != 1) {
    fit.distance_sq *= gathered.weight;
    fit.a *= gathered.weight;
    fit.b = scale(fit.b, gathered.weight);
    fit.c *= gathered.weight;
  }
  return fit;
}

double SharpCurves::distance_sq(const Gathered& gathered) const {
  double sum = 0;
  for (uint32_t id : gathered.samples) sum += samples_[id].distance_sq;
  return sum * gathered.weight;
}

void SharpCurves::unlist(VertexId v, uint32_t id) {
  auto& list = listed_at_[v];
  const auto it = std::find(list.begin(), list.end(), id);
  if (it == list.end()) return;
  *it = list.back();
  list.pop_back();
}

double SharpCurves::collapsed(VertexId vs, VertexId vt, const CollapseMesh& mesh) {
  // A job may hold sharp edges but none of their samples: the curves are updated anyway.
  if (neighbors_.empty()) return 0;  // no curves (and so no samples)
  if (samples_.empty() && neighbors_[vs].empty() && neighbors_[vt].empty()) return 0;
  std::vector<uint32_t>& moved = moved_;  // (every sample: no weights here)
  moved.assign(listed_at_[vs].begin(), listed_at_[vs].end());
  for (uint32_t id : listed_at_[vt]) {
    const Sample& s = samples_[id];
    if (s.u != vs && s.w != vs) moved.push_back(id);
  }
  for (uint32_t id : moved) {
    const Sample& s = samples_[id];
    for (VertexId end : {s.u, s.w})
      if (end != kNoId && end != vs && end != vt) unlist(end, id);
  }
  listed_at_[vs].clear();
  listed_at_[vt].clear();

  // vt's sharp edges become vs's; the edge (vs, vt) disappears.
  for (VertexId x : neighbors_[vt]) {
    if (x == vs) continue;
    erase_value(neighbors_[x], vt);
    if (!contains(neighbors_[x], vs)) neighbors_[x].push_back(vs);
    if (!contains(neighbors_[vs], x)) neighbors_[vs].push_back(x);
  }
  erase_value(neighbors_[vs], vt);
  neighbors_[vt].clear();

  const Vec3& p = mesh.position(vs);
  double max_distance_sq = 0;
  for (uint32_t id : moved) {
    Sample& s = samples_[id];
    s.u = vs;
    s.w = kNoId;
    s.distance_sq = std::numeric_limits<double>::infinity();
    for (VertexId x : neighbors_[vs]) {
      const double dist = project_on_segment(s.position, p, mesh.position(x)).distance_sq;
      if (dist < s.distance_sq) s.distance_sq = dist, s.w = x;
    }
    if (s.w == kNoId) {  // the curve is gone here (a penalised collapse): measure to vs
      const Vec3 d = sub(s.position, p);
      s.distance_sq = dot(d, d);
    }
    listed_at_[vs].push_back(id);
    if (s.w != kNoId) listed_at_[s.w].push_back(id);
    max_distance_sq = std::max(max_distance_sq, s.distance_sq);
  }
  return max_distance_sq;
}

void SharpCurves::export_state(const std::vector<VertexId>& vertices, const IdTranslation& to,
                               EnergyState& out) const {
  // Sample id -> its position in out.samples. A dense table, not a hash map: a mesh of many
  // open sheets has curve samples on most of its edges (openfoam-motorbike-332k: the hash
  // map's nodes made this 12% of a parallel build's time, and 15% more in the allocator).
  std::vector<uint32_t> index(samples_.size(), kNoId);
  out.curve_samples_total = total_samples_;
  out.sharp_begin.assign(1, 0);
  out.listed_begin.assign(1, 0);
  for (size_t i = 0; i < vertices.size(); ++i) {
    const VertexId v = vertices[i];
    // (Translated near v's own position: exact when `vertices` is the map itself, a job's.)
    for (VertexId x : sharp_neighbors(v))
      if (const VertexId written = to.near(x, i); written != kNoId)
        out.sharp_neighbors.push_back(written);
    out.sharp_begin.push_back(uint32_t(out.sharp_neighbors.size()));
    for (uint32_t id : listed_at(v)) {
      const Sample& s = samples_[id];
      const VertexId u = to.near(s.u, i), w = to.near(s.w, i);
      if (u == kNoId || (s.w != kNoId && w == kNoId)) continue;
      if (index[id] == kNoId) {
        index[id] = uint32_t(out.samples.size());
        out.samples.push_back({sample_id_.empty() ? id : sample_id_[id],
                               out.positions ? s.position : Vec3{}, s.distance_sq, u, w});
      }
      out.listed.push_back(index[id]);
    }
    out.listed_begin.push_back(uint32_t(out.listed.size()));
  }
}

void SharpCurves::import_local(const CollapseMesh& mesh, const EnergyState& state) {
  const size_t n = state.vertices.size();
  if (state.sharp_begin.size() != n + 1 || state.listed_begin.size() != n + 1)
    throw_invalid("energy state: curve lists disagree with the vertices");
  vertex_capacity_ = mesh.vertex_capacity();
  neighbors_.clear();
  listed_at_.clear();
  if (!state.sharp_neighbors.empty() || !state.listed.empty() || !state.samples.empty())
    make_lists();
  samples_.clear();
  sample_id_.clear();
  for (const EnergyState::CurveSample& s : state.samples) {
    if (s.u >= mesh.vertex_capacity() || (s.w != kNoId && s.w >= mesh.vertex_capacity()))
      throw_invalid("energy state: curve sample on a vertex out of range");
    samples_.push_back({s.position, s.distance_sq, s.u, s.w});
    sample_id_.push_back(s.id);
  }
  // Each list sized once (a job of a mesh of open sheets has lists at most of its vertices),
  // by counts that a state cannot inflate beyond its own lists (they are checked below).
  auto count = [](const std::vector<uint32_t>& begin, size_t k, size_t total) {
    return begin[k + 1] > begin[k] ? std::min<size_t>(begin[k + 1] - begin[k], total) : 0;
  };
  size_t ends = 0;
  for (size_t i = 0; i < n && !neighbors_.empty(); ++i) {
    const VertexId v = state.vertices[i];
    neighbors_[v].reserve(neighbors_[v].size() +
                          count(state.sharp_begin, i, state.sharp_neighbors.size()));
    listed_at_[v].reserve(listed_at_[v].size() + count(state.listed_begin, i, state.listed.size()));
    for (uint32_t k = state.sharp_begin[i]; k < state.sharp_begin[i + 1]; ++k) {
      if (state.sharp_neighbors.at(k) >= mesh.vertex_capacity())
        throw_invalid("energy state: sharp neighbour out of range");
      neighbors_[v].push_back(state.sharp_neighbors[k]);
    }
    ends += neighbors_[v].size();
    for (uint32_t k = state.listed_begin[i]; k < state.listed_begin[i + 1]; ++k) {
      if (state.listed.at(k) >= samples_.size())
        throw_invalid("energy state: listed sample out of range");
      listed_at_[v].push_back(state.listed[k]);
    }
  }
  edge_count_ = ends / 2;
  total_samples_ = state.curve_samples_total;
}

void SharpCurves::check_global(const EnergyState& state) const {
  const size_t n = state.vertices.size();
  if (state.sharp_begin.size() != n + 1 || state.listed_begin.size() != n + 1)
    throw_invalid("energy state: curve lists disagree with the vertices");
  for (const EnergyState::CurveSample& s : state.samples) {
    if (s.id >= samples_.size()) throw_invalid("energy state: curve sample id out of range");
    if (s.u >= vertex_capacity_ || (s.w != kNoId && s.w >= vertex_capacity_))
      throw_invalid("energy state: curve sample on a vertex out of range");
  }
  // A module without curves has no sample, and a collapse never makes a sharp edge.
  if (neighbors_.empty() && (!state.sharp_neighbors.empty() || !state.listed.empty()))
    throw_invalid("energy state: sharp curves for a mesh without any");
  for (size_t i = 0; i < n; ++i) {
    if (state.vertices[i] >= vertex_capacity_) throw_invalid("energy state: vertex out of range");
    if (state.sharp_begin[i] > state.sharp_begin[i + 1] ||
        state.sharp_begin[i + 1] > state.sharp_neighbors.size() ||
        state.listed_begin[i] > state.listed_begin[i + 1] ||
        state.listed_begin[i + 1] > state.listed.size())
      throw_invalid("energy state: curve lists out of range");
    for (uint32_t k = state.sharp_begin[i]; k < state.sharp_begin[i + 1]; ++k)
      if (state.sharp_neighbors[k] >= vertex_capacity_)
        throw_invalid("energy state: sharp neighbour out of range");
    for (uint32_t k = state.listed_begin[i]; k < state.listed_begin[i + 1]; ++k)
      if (state.listed[k] >= state.samples.size())
        throw_invalid("energy state: listed curve sample out of range");
  }
}

void SharpCurves::import_global(const EnergyState& state, const std::vector<uint32_t>* written) {
  check_global(state);
  auto write = [&](const EnergyState::CurveSample& s) {
    samples_[s.id] = {samples_[s.id].position, s.distance_sq, s.u, s.w};  // (samples never move)
  };
  if (written) {
    for (uint32_t i : *written) write(state.samples.at(i));
  } else {
    for (const EnergyState::CurveSample& s : state.samples) write(s);
  }
  if (neighbors_.empty()) return;  // (check_global: the state has no curves either)
  for (size_t i = 0; i < state.vertices.size(); ++i) {
    const VertexId v = state.vertices[i];
    neighbors_[v].assign(state.sharp_neighbors.begin() + state.sharp_begin[i],
                         state.sharp_neighbors.begin() + state.sharp_begin[i + 1]);
    listed_at_[v].clear();
    for (uint32_t k = state.listed_begin[i]; k < state.listed_begin[i + 1]; ++k)
      listed_at_[v].push_back(state.samples[state.listed[k]].id);
  }
}

}  // namespace parapm
