#include "simplify/pm_builder.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <utility>

#include "util/chunked_loops.h"
#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm {
namespace {

// Assigns PM wedge ids in order of first use and copies the values of new wedges: `values`
// are the wedges' values at the base mesh, which for a wedge the base mesh does not use is
// its value when its last face was collapsed away, the value its split brings back.
class WedgeNumbering {
 public:
  WedgeNumbering(const std::vector<float>& values, size_t wedge_count, int floats,
                 ProgressiveMesh& pm)
      : values_(values), pm_(pm), pm_id_(wedge_count, kNoId), floats_(floats) {}

  WedgeId base(WedgeId w) {
    if (pm_id_[w] == kNoId) {
      pm_id_[w] = next_++;
      pm_.base.wedge_vertex.push_back(kNoId);  // filled by the caller with the PM vertex
      pm_.base.wedge_values.insert(pm_.base.wedge_values.end(), value(w), value(w) + floats_);
    }
    return pm_id_[w];
  }
  // For a split's corner; returns the PM id and whether the wedge is new with this split.
  WedgeId split(WedgeId w, uint32_t& new_count) {
    if (pm_id_[w] == kNoId) {
      pm_id_[w] = next_++;
      ++new_count;
      pm_.new_wedge_values.insert(pm_.new_wedge_values.end(), value(w), value(w) + floats_);
    }
    return pm_id_[w];
  }
  // A wedge a split changes exists at the coarser level, so it is numbered already.
  WedgeId existing(WedgeId w) const {
    if (pm_id_[w] == kNoId) throw_internal("PM builder: a split changes a wedge not yet in use");
    return pm_id_[w];
  }

 private:
  const float* value(WedgeId w) const { return values_.data() + size_t(w) * size_t(floats_); }

  const std::vector<float>& values_;
  ProgressiveMesh& pm_;
  std::vector<WedgeId> pm_id_;
  int floats_;
  WedgeId next_ = 0;
};

// The copies made by the repair step, (copy, original) in the PM's ids, sorted: each vertex that
// came from the same input vertex as a vertex of a lesser id goes back to the least one (the
// original) when the input is restored. In `loops`' chunks: the least vertex of each input
// vertex, then each range's copies.
std::vector<std::pair<VertexId, VertexId>> vertex_copies(const RepairedMesh& repaired,
                                                         const std::vector<VertexId>& pm_vertex,
                                                         ChunkedLoops& loops) {
  const std::vector<VertexId>& input = repaired.input_vertex;
  const size_t n = input.size();
  std::vector<size_t> range_inputs(loops.ranges(n), 0);  // per range: its largest input + 1
  loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v)
      range_inputs[range] = std::max(range_inputs[range], size_t(input[v]) + 1);
  });
  const size_t inputs =
      range_inputs.empty() ? 0 : *std::max_element(range_inputs.begin(), range_inputs.end());
  std::vector<VertexId> first_of_input(inputs, kNoId);
  loops.run(n, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      std::atomic_ref<VertexId> first(first_of_input[input[v]]);
      VertexId seen = first.load(std::memory_order_relaxed);
      while (VertexId(v) < seen &&
             !first.compare_exchange_weak(seen, VertexId(v), std::memory_order_relaxed)) {
      }
    }
  });
  std::vector<std::vector<std::pair<VertexId, VertexId>>> range_copies(loops.ranges(n));
  loops.run_indexed(n, [&](size_t range, size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      const VertexId original = first_of_input[input[v]];
      if (original != VertexId(v))
        range_copies[range].emplace_back(pm_vertex[v], pm_vertex[original]);
    }
  });
  std::vector<std::pair<VertexId, VertexId>> copies;
  for (const auto& some : range_copies) copies.insert(copies.end(), some.begin(), some.end());
  std::sort(copies.begin(), copies.end());
  return copies;
}

// The records in the PM's order, read where they lie: a list, or the records' addresses.
struct RecordList {
  const std::vector<CollapseRecord>& list;
  size_t size() const { return list.size(); }
  const CollapseRecord& operator[](size_t i) const { return list[i]; }
};
struct RecordAddresses {
  std::span<const CollapseRecord* const> addresses;
  size_t size() const { return addresses.size(); }
  const CollapseRecord& operator[](size_t i) const { return *addresses[i]; }
};

// Replays the records' wedge value changes from the input's values: returns the values at the
// base mesh and, per change in record order, the values it replaced (floats each).
template <typename Records>
std::vector<float> replay_wedge_changes(const Mesh& mesh, const Records& records,
                                        std::vector<float>& replaced) {
  const size_t floats = size_t(mesh.layout.floats_per_wedge());
  std::vector<float> values = mesh.wedge_values;
  for (size_t i = 0; i < records.size(); ++i) {
    const CollapseRecord& r = records[i];
    if (r.changed_values.size() != r.changed_wedges.size() * floats)
      throw_internal("PM builder: a record's wedge changes and values disagree");
    for (size_t c = 0; c < r.changed_wedges.size(); ++c) {
      float* current = values.data() + size_t(r.changed_wedges[c]) * floats;
      replaced.insert(replaced.end(), current, current + floats);
      std::copy_n(r.changed_values.data() + c * floats, floats, current);
    }
  }
  return values;
}

template <typename Records, typename FinalMesh>
ProgressiveMesh build_pm(const RepairedMesh& repaired, const FinalMesh& final_mesh,
                         const Records& records, const PmBuildOptions& options) {
  ChunkedLoops one_thread;
  ChunkedLoops& loops = options.loops ? *options.loops : one_thread;
  const Mesh& mesh = repaired.mesh;
  const size_t splits = records.size();
  ProgressiveMesh pm;
  pm.info.input_vertices = repaired.input_vertex_count;
  pm.info.input_faces = repaired.input_face_count;
  pm.base.layout = mesh.layout;
  pm.base.positions_are_float = mesh.positions_are_float;

  // Vertices: the survivors (and isolated vertices) in their original order, then one per
  // split, the vt of the collapses taken last to first. (A vertex collapses away once: the
  // chunks mark distinct vertices; relaxed stores all the same, should records repeat one.)
  std::vector<uint8_t> removed(mesh.vertex_count(), 0);
  loops.run(splits, [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i)
      std::atomic_ref<uint8_t>(removed[records[i].vt]).store(1, std::memory_order_relaxed);
  });
  KeptItems survivors =
      number_kept(loops, mesh.vertex_count(), [&](size_t v) { return removed[v] == 0; });
  std::vector<VertexId> pm_vertex = std::move(survivors.new_id);
  const size_t base_vertices = survivors.old_id.size();
  pm.base.positions.resize(base_vertices);
  loops.run(base_vertices, [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v)
      pm.base.positions[v] = final_mesh.position(survivors.old_id[v]);
  });
  // Split j brings back the vt of record splits - 1 - j.
  auto record_of = [&](size_t j) -> const CollapseRecord& { return records[splits - 1 - j]; };
  loops.run(splits, [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) pm_vertex[record_of(j).vt] = VertexId(base_vertices + j);
  });

  // Faces: the survivors in their original order, then fl, fr of each split.
  KeptItems alive = number_kept(loops, mesh.face_count(),
                                [&](size_t f) { return final_mesh.face_alive(FaceId(f)); });
  std::vector<FaceId> pm_face = std::move(alive.new_id);
  const size_t base_faces = alive.old_id.size();
  pm.base.faces.resize(base_faces);
  loops.run(base_faces, [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j) {
      const Triangle& t = final_mesh.face(alive.old_id[j]);
      pm.base.faces[j] = {pm_vertex[t[0]], pm_vertex[t[1]], pm_vertex[t[2]]};
    }
  });
  const bool attributes = mesh.layout.any();
  const size_t floats = size_t(mesh.layout.floats_per_wedge());
  std::vector<float> replaced;  // per wedge change, in record order: the values before it
  const std::vector<float> base_values =
      attributes ? replay_wedge_changes(mesh, records, replaced) : std::vector<float>{};
  WedgeNumbering wedges(base_values, mesh.wedge_count(), int(floats), pm);
  if (attributes) {
    // Wedges are numbered in order of first use: one pass, in the faces' order.
    pm.base.face_wedges.reserve(base_faces);
    for (size_t j = 0; j < base_faces; ++j) {
      const FaceId f = alive.old_id[j];
      const Triangle& t = final_mesh.face(f);
      std::array<WedgeId, 3> w;
      for (int k = 0; k < 3; ++k) {
        w[k] = wedges.base(mesh.face_wedges[f][k]);
        pm.base.wedge_vertex[w[k]] = pm_vertex[t[k]];
      }
      pm.base.face_wedges.push_back(w);
    }
  }

  // The error bound of each record: the running maximum of the costs, so that the bound never
  // decreases with coarsening (per range, then each range from the maximum before it).
  std::vector<float> range_max(loops.ranges(splits), 0);
  loops.run_indexed(splits, [&](size_t range, size_t begin, size_t end) {
    float bound = 0;
    for (size_t i = begin; i < end; ++i) bound = std::max(bound, records[i].error);
    range_max[range] = bound;
  });
  std::vector<float> bound(splits);
  std::vector<size_t> new_faces(loops.ranges(splits) + 1, 0);  // before each range of splits
  loops.run_indexed(splits, [&](size_t range, size_t begin, size_t end) {
    float before = 0;
    for (size_t r = 0; r < range; ++r) before = std::max(before, range_max[r]);
    for (size_t i = begin; i < end; ++i) {
      before = std::max(before, records[i].error);
      bound[i] = before;
    }
    size_t count = 0;
    for (size_t j = begin; j < end; ++j) {
      const CollapseRecord& r = record_of(j);
      if (r.to_complete)
        throw_internal("build_pm_from_collapses: a record the replay did not complete");
      if (!attributes && !r.changed_values.empty())
        throw_internal("PM builder: a record's wedge changes and values disagree");
      count += (r.fl != kNoId ? 1 : 0) + (r.fr != kNoId ? 1 : 0);
    }
    new_faces[range + 1] = count;
  });
  for (size_t r = 0; r + 1 < new_faces.size(); ++r) new_faces[r + 1] += new_faces[r];
  resize_touched(pm.splits, splits, loops);
  loops.run_indexed(splits, [&](size_t range, size_t begin, size_t end) {
    FaceId next_face = FaceId(base_faces + new_faces[range]);
    for (size_t j = begin; j < end; ++j) {
      const size_t i = splits - 1 - j;
      const CollapseRecord& r = records[i];
      VertexSplit& s = pm.splits[j];
      s.vs = pm_vertex[r.vs];
      s.vl = r.vl == kNoId ? kNoId : pm_vertex[r.vl];
      s.vr = r.vr == kNoId ? kNoId : pm_vertex[r.vr];
      s.error = bound[i];
      s.vs_before = r.position;
      s.vs_after = r.vs_position;
      s.vt_after = r.vt_position;
      for (FaceId f : {r.fl, r.fr})
        if (f != kNoId) pm_face[f] = next_face++;
    }
  });
  if (attributes) {
    // Where each record's changes start in `replaced`.
    std::vector<size_t> replaced_begin(splits + 1, 0);
    for (size_t i = 0; i < splits; ++i)
      replaced_begin[i + 1] = replaced_begin[i] + records[i].changed_wedges.size() * floats;
    // Wedges new with a split are numbered in the splits' order: one pass.
    for (size_t j = 0; j < splits; ++j) {
      const size_t i = splits - 1 - j;
      const CollapseRecord& r = records[i];
      VertexSplit& s = pm.splits[j];
      for (int k = 0; k < 6; ++k)
        if (r.corner_wedges[k] != kNoId)
          s.corner_wedges[k] = wedges.split(r.corner_wedges[k], s.new_wedge_count);
      // The split undoes the collapse's changes: coarse (after the collapse), then fine.
      s.wedge_changes_begin = uint32_t(pm.wedge_changes.size());
      s.wedge_changes_count = uint32_t(r.changed_wedges.size());
      for (size_t c = 0; c < r.changed_wedges.size(); ++c) {
        pm.wedge_changes.push_back(
            {wedges.existing(r.changed_wedges[c]), uint32_t(pm.wedge_change_values.size())});
        const float* coarse = r.changed_values.data() + c * floats;
        const float* fine = replaced.data() + replaced_begin[i] + c * floats;
        pm.wedge_change_values.insert(pm.wedge_change_values.end(), coarse, coarse + floats);
        pm.wedge_change_values.insert(pm.wedge_change_values.end(), fine, fine + floats);
      }
    }
  }
  if (base_vertices + splits != mesh.vertex_count() ||
      base_faces + new_faces.back() != mesh.face_count())
    throw_internal("PM builder: the collapses do not account for every vertex and face");

  pm.vertex_copies = vertex_copies(repaired, pm_vertex, loops);
  if (options.keep_order) {
    // pm_vertex and pm_face are permutations: each chunk writes its own entries.
    pm.input_vertex_order.assign(mesh.vertex_count(), 0);
    loops.run(mesh.vertex_count(), [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v)
        pm.input_vertex_order[pm_vertex[v]] = repaired.input_vertex[v];
    });
    pm.input_face_order.assign(mesh.face_count(), 0);
    loops.run(mesh.face_count(), [&](size_t begin, size_t end) {
      for (size_t f = begin; f < end; ++f) pm.input_face_order[pm_face[f]] = repaired.input_face[f];
    });
  }
  return pm;
}

}  // namespace

ProgressiveMesh build_pm_from_collapses(const RepairedMesh& repaired,
                                        const CollapseMesh& final_mesh,
                                        const std::vector<CollapseRecord>& records,
                                        const PmBuildOptions& options) {
  return build_pm(repaired, final_mesh, RecordList{records}, options);
}

ProgressiveMesh build_pm_from_collapses(const RepairedMesh& repaired,
                                        const CollapseMesh& final_mesh,
                                        std::span<const CollapseRecord* const> records,
                                        const PmBuildOptions& options) {
  return build_pm(repaired, final_mesh, RecordAddresses{records}, options);
}

ProgressiveMesh build_pm_from_collapses(const RepairedMesh& repaired,
                                        const PartlyCopiedMesh& final_mesh,
                                        std::span<const CollapseRecord* const> records,
                                        const PmBuildOptions& options) {
  return build_pm(repaired, final_mesh, RecordAddresses{records}, options);
}

}  // namespace parapm
