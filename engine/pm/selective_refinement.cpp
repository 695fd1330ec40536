// Selective refinement (selective_refinement.h). The splits are applied out of the PM's
// sequence, so vertex ids are not contiguous: the FanMesh is sized for every vertex of the
// full mesh and a presence flag says which exist. Wedge values of the whole PM are loaded at
// once (a wedge's values are known from its creating split), and wedge changes of applied
// splits overwrite them with their fine values.
#include "pm/selective_refinement.h"

#include <string>

#include "pm/fan_mesh.h"
#include "pm/mesh_assembly.h"
#include "util/error.h"

namespace parapm {

namespace {
std::string str(uint64_t value) { return std::to_string(value); }
}  // namespace

SelectiveRefinement selectively_refine(const ProgressiveMesh& pm, const RefinePredicate& refine) {
  const Mesh& base = pm.base;
  const size_t n0 = base.vertex_count();
  const size_t n_full = pm.full_vertex_count();
  const bool attributes = base.layout.any();
  const size_t fpw = size_t(base.layout.floats_per_wedge());
  const size_t full_wedges = pm.full_wedge_count();

  FanMesh mesh(base, attributes);
  if (n_full > n0) mesh.ensure_vertex(VertexId(n_full - 1));
  std::vector<uint8_t> present(n_full, 0);
  std::fill(present.begin(), present.begin() + n0, 1);
  std::vector<float> wedge_values;
  if (attributes) {
    if (base.wedge_values.size() != base.wedge_count() * fpw ||
        pm.new_wedge_values.size() != (full_wedges - base.wedge_count()) * fpw)
      throw_invalid("selective refinement: wedge values do not match the wedge counts");
    wedge_values = base.wedge_values;
    wedge_values.insert(wedge_values.end(), pm.new_wedge_values.begin(), pm.new_wedge_values.end());
  }

  SelectiveRefinement result;
  std::vector<FaceId> fan;
  for (size_t i = 0; i < pm.splits.size(); ++i) {
    const VertexSplit& s = pm.splits[i];
    const VertexId vt = VertexId(n0 + i);
    // Start loading what the next two splits read (as PmCursor does).
    if (i + 2 < pm.splits.size()) {
      const VertexSplit& later = pm.splits[i + 2];
      mesh.prefetch_vertex(later.vs);
      mesh.prefetch_vertex(later.vl);
      mesh.prefetch_vertex(later.vr);
    }
    if (i + 1 < pm.splits.size()) mesh.prefetch_faces_of(pm.splits[i + 1].vs);
    const auto corrupt = [&](const std::string& what) {
      throw_invalid("selective refinement: vsplit " + str(i) + ": " + what);
    };
    if (s.vs >= vt || (s.vl != kNoId && s.vl >= vt) || (s.vr != kNoId && s.vr >= vt))
      corrupt("a vertex id is out of range");
    if ((!s.has_fl() && !s.has_fr()) || s.vl == s.vr || s.vl == s.vs || s.vr == s.vs)
      corrupt("vs, vl and vr are not distinct");
    if (attributes) {
      for (int k = 0; k < 6; ++k)
        if ((k < 3 ? s.has_fl() : s.has_fr()) && s.corner_wedges[k] >= full_wedges)
          corrupt("a corner wedge is out of range");
      if (uint64_t(s.wedge_changes_begin) + s.wedge_changes_count > pm.wedge_changes.size())
        corrupt("wedge changes out of range");
    }

    if (!present[s.vs] || (s.has_fl() && !present[s.vl]) || (s.has_fr() && !present[s.vr])) {
      ++result.skipped_absent;
      continue;
    }
    if (!mesh.find_fan(s, fan).empty()) {
      ++result.skipped_inapplicable;
      continue;
    }
    if (!refine(s.vs, mesh.positions()[s.vs])) {
      ++result.skipped_by_predicate;
      continue;
    }
    mesh.split(s, vt, fan);
    mesh.set_position(s.vs, s.vs_after);
    mesh.set_position(vt, s.vt_after);
    present[vt] = 1;
    for (uint32_t c = 0; c < s.wedge_changes_count; ++c) {
      const WedgeChange& change = pm.wedge_changes[s.wedge_changes_begin + c];
      if (change.wedge >= full_wedges ||
          uint64_t(change.values_offset) + 2 * fpw > pm.wedge_change_values.size())
        corrupt("a wedge change is out of range");
      const float* fine = pm.wedge_change_values.data() + change.values_offset + fpw;
      std::copy(fine, fine + fpw, wedge_values.begin() + change.wedge * fpw);
    }
    ++result.applied;
  }

  // Compact: present vertices keep their relative order.
  std::vector<VertexId> compact(n_full, kNoId);
  std::vector<Vec3> positions;
  for (VertexId v = 0; v < n_full; ++v) {
    if (!present[v]) continue;
    compact[v] = VertexId(positions.size());
    positions.push_back(mesh.positions()[v]);
    result.pm_vertex.push_back(v);
  }
  std::vector<Triangle> faces = mesh.faces();
  for (Triangle& t : faces)
    for (VertexId& v : t) v = compact[v];
  result.mesh = assemble_mesh(std::move(positions), std::move(faces), mesh.face_wedges(),
                              wedge_values, base.layout, base.positions_are_float);
  return result;
}

}  // namespace parapm
