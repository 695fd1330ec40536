#include "simplify/pm_builder.h"

#include <algorithm>

#include "util/error.h"

namespace parapm {
namespace {

// Assigns PM wedge ids in order of first use and copies the values of new wedges.
class WedgeNumbering {
 public:
  WedgeNumbering(const Mesh& mesh, ProgressiveMesh& pm)
      : mesh_(mesh),
        pm_(pm),
        pm_id_(mesh.wedge_count(), kNoId),
        floats_(mesh.layout.floats_per_wedge()) {}

  WedgeId base(WedgeId w) {
    if (pm_id_[w] == kNoId) {
      pm_id_[w] = next_++;
      pm_.base.wedge_vertex.push_back(kNoId);  // filled by the caller with the PM vertex
      pm_.base.wedge_values.insert(pm_.base.wedge_values.end(), mesh_.wedge(w),
                                   mesh_.wedge(w) + floats_);
    }
    return pm_id_[w];
  }
  // For a split's corner; returns the PM id and whether the wedge is new with this split.
  WedgeId split(WedgeId w, uint32_t& new_count) {
    if (pm_id_[w] == kNoId) {
      pm_id_[w] = next_++;
      ++new_count;
      pm_.new_wedge_values.insert(pm_.new_wedge_values.end(), mesh_.wedge(w),
                                  mesh_.wedge(w) + floats_);
    }
    return pm_id_[w];
  }

 private:
  const Mesh& mesh_;
  ProgressiveMesh& pm_;
  std::vector<WedgeId> pm_id_;
  int floats_;
  WedgeId next_ = 0;
};

}  // namespace

ProgressiveMesh build_pm_from_collapses(const RepairedMesh& repaired,
                                        const CollapseMesh& final_mesh,
                                        const std::vector<CollapseRecord>& records,
                                        const PmBuildOptions& options) {
  const Mesh& mesh = repaired.mesh;
  ProgressiveMesh pm;
  pm.info.input_vertices = repaired.input_vertex_count;
  pm.info.input_faces = repaired.input_face_count;
  pm.base.layout = mesh.layout;
  pm.base.positions_are_float = mesh.positions_are_float;

  // Vertices: the survivors (and isolated vertices) in their original order, then one per
  // split, the vt of the collapses taken last to first.
  std::vector<VertexId> pm_vertex(mesh.vertex_count(), kNoId);
  std::vector<uint8_t> removed(mesh.vertex_count(), 0);
  for (const CollapseRecord& r : records) removed[r.vt] = 1;
  VertexId next_vertex = 0;
  for (VertexId v = 0; v < mesh.vertex_count(); ++v) {
    if (removed[v]) continue;
    pm_vertex[v] = next_vertex++;
    pm.base.positions.push_back(final_mesh.position(v));
  }
  for (size_t i = records.size(); i-- > 0;) pm_vertex[records[i].vt] = next_vertex++;

  // Faces: the survivors in their original order, then fl, fr of each split.
  std::vector<FaceId> pm_face(mesh.face_count(), kNoId);
  FaceId next_face = 0;
  WedgeNumbering wedges(mesh, pm);
  const bool attributes = mesh.layout.any();
  for (FaceId f = 0; f < mesh.face_count(); ++f) {
    if (!final_mesh.face_alive(f)) continue;
    pm_face[f] = next_face++;
    const Triangle& t = final_mesh.face(f);
    pm.base.faces.push_back({pm_vertex[t[0]], pm_vertex[t[1]], pm_vertex[t[2]]});
    if (attributes) {
      std::array<WedgeId, 3> w;
      for (int k = 0; k < 3; ++k) {
        w[k] = wedges.base(mesh.face_wedges[f][k]);
        pm.base.wedge_vertex[w[k]] = pm_vertex[t[k]];
      }
      pm.base.face_wedges.push_back(w);
    }
  }

  pm.splits.reserve(records.size());
  float error_bound = 0;  // running maximum, so that the bound never decreases with coarsening
  std::vector<float> bound(records.size());
  for (size_t i = 0; i < records.size(); ++i) {
    error_bound = std::max(error_bound, records[i].error);
    bound[i] = error_bound;
  }
  for (size_t i = records.size(); i-- > 0;) {
    const CollapseRecord& r = records[i];
    VertexSplit s;
    s.vs = pm_vertex[r.vs];
    s.vl = r.vl == kNoId ? kNoId : pm_vertex[r.vl];
    s.vr = r.vr == kNoId ? kNoId : pm_vertex[r.vr];
    s.error = bound[i];
    s.vs_before = r.position;
    s.vs_after = r.vs_position;
    s.vt_after = r.vt_position;
    if (attributes) {
      for (int k = 0; k < 6; ++k)
        if (r.corner_wedges[k] != kNoId)
          s.corner_wedges[k] = wedges.split(r.corner_wedges[k], s.new_wedge_count);
    }
    for (FaceId f : {r.fl, r.fr})
      if (f != kNoId) pm_face[f] = next_face++;
    pm.splits.push_back(s);
  }
  if (next_vertex != mesh.vertex_count() || next_face != mesh.face_count())
    throw_internal("PM builder: the collapses do not account for every vertex and face");

  // Copies made by the repair step go back to their original (the first vertex that came
  // from the same input vertex) when the input is restored.
  std::vector<VertexId> first_of_input;
  for (VertexId v = 0; v < mesh.vertex_count(); ++v) {
    const VertexId in = repaired.input_vertex[v];
    if (in >= first_of_input.size()) first_of_input.resize(size_t(in) + 1, kNoId);
    if (first_of_input[in] == kNoId)
      first_of_input[in] = v;
    else
      pm.vertex_copies.emplace_back(pm_vertex[v], pm_vertex[first_of_input[in]]);
  }
  std::sort(pm.vertex_copies.begin(), pm.vertex_copies.end());

  if (options.keep_order) {
    pm.input_vertex_order.assign(mesh.vertex_count(), 0);
    for (VertexId v = 0; v < mesh.vertex_count(); ++v)
      pm.input_vertex_order[pm_vertex[v]] = repaired.input_vertex[v];
    pm.input_face_order.assign(mesh.face_count(), 0);
    for (FaceId f = 0; f < mesh.face_count(); ++f)
      pm.input_face_order[pm_face[f]] = repaired.input_face[f];
  }
  return pm;
}

}  // namespace parapm
