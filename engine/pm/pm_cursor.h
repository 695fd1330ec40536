// PmCursor: the mesh at one level of a Progressive Mesh, moved up and down the levels by
// applying and undoing vertex splits (Hoppe 96 section 3; the iterator of Hoppe's libHh
// PMesh.h). Level k is the base mesh after splits 0..k-1: vertices 0..n0+k-1, the base faces
// plus fl, fr of each applied split, the base wedges plus each applied split's new wedges.
//
// Cost: apply_next() and undo_last() take time proportional to the valence of vs (fan_mesh.h);
// undo is exact: positions and wedge values come back bit for bit (vs_before, the coarse
// values of wedge changes), faces and corner wedges are the same. Not thread-safe; several
// cursors may share one PM.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "mesh/mesh.h"
#include "pm/fan_mesh.h"
#include "pm/progressive_mesh.h"

namespace parapm {

class PmCursor {
 public:
  // Starts at level 0 (the base mesh). `pm` must outlive the cursor. Splits and their wedge
  // data may be appended to `pm` while the cursor exists (a PM being received as a stream);
  // nothing else in it may change.
  explicit PmCursor(const ProgressiveMesh& pm);

  size_t level() const { return level_; }
  size_t max_level() const { return pm_->splits.size(); }

  // Applies split level(). Throws Error(kInvalidInput) when there is none, or when the split
  // does not fit the mesh (ids out of range, vl or vr not adjacent to vs, a fan that does not
  // close: a corrupt PM); the cursor is then unchanged.
  void apply_next();
  // Undoes split level()-1. Throws Error(kInvalidInput) at level 0.
  void undo_last();
  // Applies or undoes splits until level() == level; throws when level > max_level().
  void go_to_level(size_t level);

  size_t vertex_count() const { return mesh_.vertex_count(); }
  size_t face_count() const { return mesh_.face_count(); }
  size_t wedge_count() const { return fpw_ == 0 ? 0 : wedge_values_.size() / fpw_; }

  const std::vector<Vec3>& positions() const { return mesh_.positions(); }
  const std::vector<Triangle>& faces() const { return mesh_.faces(); }
  // PM wedge ids per corner; empty when the PM has no attributes.
  const std::vector<std::array<WedgeId, 3>>& face_wedges() const { return mesh_.face_wedges(); }
  // floats_per_wedge values per PM wedge existing at this level.
  const std::vector<float>& wedge_values() const { return wedge_values_; }
  // Faces incident to v, in no particular order.
  std::span<const FaceId> faces_of(VertexId v) const { return mesh_.faces_of(v); }

  // The current level as a Mesh: all its vertices and faces in PM order, wedges as the
  // distinct (corner vertex, PM wedge) pairs (mesh_assembly.h), positions_are_float as in the
  // PM's base mesh.
  Mesh extract() const;

 private:
  void check_split(const VertexSplit& s) const;

  const ProgressiveMesh* pm_;
  FanMesh mesh_;
  std::vector<float> wedge_values_;
  size_t level_ = 0;
  size_t fpw_ = 0;  // floats per wedge, 0 without attributes
  std::vector<FaceId> fan_;
};

}  // namespace parapm
