#include "parallel/subset_job.h"

#include <algorithm>
#include <utility>

#include "util/error.h"
#include "util/zeroed_array.h"

namespace parapm {
namespace {

// Local id of `global` in the sorted list `ids` (present by construction).
uint32_t local_of(const std::vector<uint32_t>& ids, uint32_t global) {
  return uint32_t(std::lower_bound(ids.begin(), ids.end(), global) - ids.begin());
}

// Per thread (jobs are built concurrently, one per pool task), a stamp and a slot per element
// of the whole mesh: the extraction collects each face and vertex once, and finds a corner's
// local id, without sorting every corner or searching for it (either would be a large part of
// the quadric's parallel build). Zeroed pages: a thread holds memory for the ids of the
// regions it extracted, not for the whole mesh.
class Marks {
 public:
  void begin(size_t size) {
    if (stamp_.size() < size) {  // (fresh stamps: all below the generation)
      stamp_.assign_zeroed(size);
      slot_.assign_zeroed(size);
    }
    if (++generation_ == 0) {  // wrapped: forget every stamp
      stamp_.assign_zeroed(stamp_.size());
      generation_ = 1;
    }
  }
  bool first_visit(uint32_t id) {  // true once per id between begin() calls
    if (stamp_[id] == generation_) return false;
    stamp_[id] = generation_;
    return true;
  }
  bool visited(uint32_t id) const { return stamp_[id] == generation_; }
  uint32_t& slot(uint32_t id) { return slot_[id]; }

 private:
  ZeroedArray<uint32_t> stamp_, slot_;
  uint32_t generation_ = 0;
};

}  // namespace

void to_global_ids(CollapseRecord& r, const SubsetJob& job) {
  auto vertex = [&](VertexId v) { return v == kNoId ? kNoId : job.global_vertex[v]; };
  auto face = [&](FaceId f) { return f == kNoId ? kNoId : job.global_face[f]; };
  auto wedge = [&](WedgeId w) { return w == kNoId ? kNoId : job.global_wedge[w]; };
  r.vs = vertex(r.vs);
  r.vt = vertex(r.vt);
  r.vl = vertex(r.vl);
  r.vr = vertex(r.vr);
  r.fl = face(r.fl);
  r.fr = face(r.fr);
  for (WedgeId& w : r.corner_wedges) w = wedge(w);
  for (WedgeId& w : r.changed_wedges) w = wedge(w);
}

SubsetJob extract_subset(const CollapseMesh& mesh, const AttributeLayout& layout,
                         const std::vector<float>& wedge_values, bool positions_are_float,
                         const std::vector<uint8_t>& locked,
                         const std::vector<uint32_t>& vertex_subset,
                         const std::vector<VertexId>& owned_vertices, uint32_t subset,
                         uint32_t round, const SubsetOptions& options, const CopyGroups* groups) {
  SubsetJob job;
  job.round = round;
  job.subset = subset;
  job.options = options;
  // Mixed per round and subset, so that subsets do not draw the same sequence.
  job.options.seed = options.seed + 0x9E3779B97F4A7C15ull * (uint64_t(round) * 257 + subset + 1);

  // Faces: every live face around an owned vertex (the subset's faces and the halo).
  thread_local Marks face_marks, vertex_marks;
  face_marks.begin(mesh.face_capacity());
  for (VertexId v : owned_vertices)
    for (FaceId f : mesh.faces_of(v))
      if (face_marks.first_visit(f)) job.global_face.push_back(f);
  std::sort(job.global_face.begin(), job.global_face.end());
  // Vertices: the corners of those faces.
  vertex_marks.begin(mesh.vertex_capacity());
  for (FaceId f : job.global_face)
    for (VertexId v : mesh.face(f))
      if (vertex_marks.first_visit(v)) job.global_vertex.push_back(v);
  std::sort(job.global_vertex.begin(), job.global_vertex.end());
  for (size_t i = 0; i < job.global_vertex.size(); ++i)
    vertex_marks.slot(job.global_vertex[i]) = uint32_t(i);

  Mesh& out = job.mesh;
  out.positions_are_float = positions_are_float;
  out.positions.reserve(job.global_vertex.size());
  job.owned.reserve(job.global_vertex.size());
  job.locked.reserve(job.global_vertex.size());
  for (VertexId g : job.global_vertex) {
    out.positions.push_back(mesh.position(g));
    job.owned.push_back(vertex_subset[g] == subset ? 1 : 0);
    job.locked.push_back(!locked.empty() && locked[g] ? 1 : 0);
  }
  if (groups && !groups->empty()) {
    // A group is the job's when every live copy of it is here; named by its first one here.
    job.copy_group.assign(job.global_vertex.size(), kNoId);
    for (size_t i = 0; i < job.global_vertex.size(); ++i) {
      const VertexId g = job.global_vertex[i];
      if (!groups->is_copy(g)) continue;
      uint32_t name = kNoId;
      bool whole = true;
      for (VertexId copy : groups->of(groups->group[g])) {
        if (!mesh.vertex_alive(copy)) continue;
        whole = whole && vertex_marks.visited(copy);
        if (whole && name == kNoId) name = vertex_marks.slot(copy);
      }
      if (whole) job.copy_group[i] = name;
    }
    if (std::ranges::all_of(job.copy_group, [](uint32_t g) { return g == kNoId; }))
      job.copy_group.clear();
  }
  out.faces.reserve(job.global_face.size());
  for (FaceId f : job.global_face) {
    const Triangle& t = mesh.face(f);
    Triangle local;
    bool all_owned = true;
    for (int k = 0; k < 3; ++k) {
      local[k] = vertex_marks.slot(t[k]);
      all_owned = all_owned && job.owned[local[k]];
    }
    out.faces.push_back(local);
    if (all_owned) ++job.owned_faces;
  }

  if (layout.any() && mesh.has_wedges()) {
    out.layout = layout;
    for (FaceId f : job.global_face)
      for (WedgeId w : mesh.corner_wedges(f)) job.global_wedge.push_back(w);
    std::sort(job.global_wedge.begin(), job.global_wedge.end());
    job.global_wedge.erase(std::unique(job.global_wedge.begin(), job.global_wedge.end()),
                           job.global_wedge.end());
    const size_t floats = size_t(layout.floats_per_wedge());
    out.wedge_vertex.assign(job.global_wedge.size(), kNoId);
    out.wedge_values.reserve(job.global_wedge.size() * floats);
    for (WedgeId g : job.global_wedge)
      out.wedge_values.insert(out.wedge_values.end(), wedge_values.begin() + ptrdiff_t(g * floats),
                              wedge_values.begin() + ptrdiff_t((g + 1) * floats));
    out.face_wedges.reserve(job.global_face.size());
    for (size_t i = 0; i < job.global_face.size(); ++i) {
      const auto& w = mesh.corner_wedges(job.global_face[i]);
      std::array<WedgeId, 3> local;
      for (int k = 0; k < 3; ++k) {
        local[k] = local_of(job.global_wedge, w[k]);
        out.wedge_vertex[local[k]] = out.faces[i][k];  // a wedge's corners share one vertex
      }
      out.face_wedges.push_back(local);
    }
  }
  return job;
}

std::vector<std::vector<VertexId>> owned_vertices(const CollapseMesh& mesh,
                                                  const std::vector<uint32_t>& vertex_subset,
                                                  uint32_t subsets) {
  ChunkedLoops one_thread;
  return owned_vertices(mesh, vertex_subset, subsets, one_thread);
}

std::vector<std::vector<VertexId>> owned_vertices(const CollapseMesh& mesh,
                                                  const std::vector<uint32_t>& vertex_subset,
                                                  uint32_t subsets, ChunkedLoops& loops) {
  const size_t n = mesh.vertex_capacity();
  if (vertex_subset.size() != n)
    throw_invalid("extract_subsets: the partition has " + std::to_string(vertex_subset.size()) +
                  " vertices, the mesh " + std::to_string(n));
  // Per range of vertices, its count in each subset, then where its vertices go in each list.
  std::vector<std::vector<size_t>> at(loops.ranges(n), std::vector<size_t>(subsets, 0));
  loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      if (!mesh.vertex_alive(VertexId(v))) continue;
      if (vertex_subset[v] >= subsets)
        throw_invalid("extract_subsets: vertex " + std::to_string(v) + " has subset " +
                      std::to_string(vertex_subset[v]) + " of " + std::to_string(subsets));
      ++at[range][vertex_subset[v]];
    }
  });
  std::vector<std::vector<VertexId>> owned(subsets);
  for (uint32_t k = 0; k < subsets; ++k) {
    size_t total = 0;
    for (std::vector<size_t>& range : at) total += std::exchange(range[k], total);
    owned[k].resize(total);
  }
  loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
    std::vector<size_t>& next = at[range];
    for (size_t v = begin; v < end; ++v)
      if (mesh.vertex_alive(VertexId(v)))
        owned[vertex_subset[v]][next[vertex_subset[v]]++] = VertexId(v);
  });
  return owned;
}

std::vector<SubsetJob> extract_subsets(const CollapseMesh& mesh, const AttributeLayout& layout,
                                       const std::vector<float>& wedge_values,
                                       bool positions_are_float, const std::vector<uint8_t>& locked,
                                       const std::vector<uint32_t>& vertex_subset, uint32_t subsets,
                                       uint32_t round, const SubsetOptions& options,
                                       const CopyGroups* groups) {
  const std::vector<std::vector<VertexId>> owned = owned_vertices(mesh, vertex_subset, subsets);
  std::vector<SubsetJob> jobs;
  jobs.reserve(subsets);
  for (uint32_t s = 0; s < subsets; ++s)
    jobs.push_back(extract_subset(mesh, layout, wedge_values, positions_are_float, locked,
                                  vertex_subset, owned[s], s, round, options, groups));
  return jobs;
}

void validate_subset_job(const SubsetJob& job) {
  const Mesh& m = job.mesh;
  const std::string name = "subset job " + std::to_string(job.subset) + ": ";
  auto increasing = [&](const std::vector<uint32_t>& ids, const char* what) {
    for (size_t i = 1; i < ids.size(); ++i)
      if (!(ids[i - 1] < ids[i])) throw_invalid(name + what + " ids are not increasing");
  };
  if (job.global_vertex.size() != m.vertex_count() || job.owned.size() != m.vertex_count() ||
      job.locked.size() != m.vertex_count())
    throw_invalid(name + "per-vertex arrays disagree with the mesh");
  if (!job.copy_group.empty() && job.copy_group.size() != m.vertex_count())
    throw_invalid(name + "copy groups disagree with the mesh");
  for (uint32_t g : job.copy_group)
    if (g != kNoId && g >= m.vertex_count()) throw_invalid(name + "copy group out of range");
  if (job.global_face.size() != m.face_count()) throw_invalid(name + "face map size");
  if (job.global_wedge.size() != m.wedge_count()) throw_invalid(name + "wedge map size");
  if (!m.face_wedges.empty() && m.face_wedges.size() != m.face_count())
    throw_invalid(name + "corner wedges size");
  if (m.wedge_values.size() != m.wedge_count() * size_t(m.layout.floats_per_wedge()))
    throw_invalid(name + "wedge values size");
  increasing(job.global_vertex, "vertex");
  increasing(job.global_face, "face");
  increasing(job.global_wedge, "wedge");
  for (FaceId f = 0; f < m.face_count(); ++f) {
    bool touches = false;
    for (int k = 0; k < 3; ++k) {
      const VertexId v = m.faces[f][k];
      if (v >= m.vertex_count()) throw_invalid(name + "face " + std::to_string(f) + " corner");
      touches = touches || job.owned[v];
      if (!m.face_wedges.empty() && m.face_wedges[f][k] >= m.wedge_count())
        throw_invalid(name + "face " + std::to_string(f) + " wedge");
    }
    if (!touches) throw_invalid(name + "face " + std::to_string(f) + " touches no owned vertex");
  }
  // The job looks its deferred edges up by (a, b) (simplifier.h, first_deferred).
  for (size_t i = 0; i < job.deferred.size(); ++i) {
    const DeferredEdge& d = job.deferred[i];
    if (d.a >= d.b || d.b >= m.vertex_count() ||
        (i > 0 && !(job.deferred[i - 1].a < d.a ||
                    (job.deferred[i - 1].a == d.a && job.deferred[i - 1].b < d.b))))
      throw_invalid(name + "deferred edge " + std::to_string(i) +
                    " out of range or not sorted once by (a, b)");
  }
}

SubsetOptions subset_options_of(const SimplifyOptions& options, const Mesh& mesh) {
  SubsetOptions s;
  copy_metric_options(options, s);
  s.reference_diagonal = bounding_box(mesh).diagonal();
  return s;
}

}  // namespace parapm
