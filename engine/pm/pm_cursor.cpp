// PmCursor (pm_cursor.h): sequential application and exact undo of vertex splits. The
// topology is FanMesh's; this file adds the PM's numbering (vt = n0 + i, new wedges appended),
// the positions and the wedge values, and the cheap range checks that keep a corrupt PM from
// indexing out of bounds even when nobody called validate_pm().
#include "pm/pm_cursor.h"

#include <algorithm>
#include <string>

#include "pm/mesh_assembly.h"
#include "util/error.h"

namespace parapm {

namespace {
std::string str(uint64_t value) { return std::to_string(value); }
}  // namespace

PmCursor::PmCursor(const ProgressiveMesh& pm)
    : pm_(&pm),
      mesh_(pm.base, pm.base.layout.any()),
      wedge_values_(pm.base.layout.any() ? pm.base.wedge_values : std::vector<float>{}),
      fpw_(size_t(pm.base.layout.floats_per_wedge())) {
  if (fpw_ != 0 &&
      (wedge_values_.size() % fpw_ != 0 || wedge_values_.size() / fpw_ != pm.base.wedge_count()))
    throw_invalid("base mesh: wedge values do not match the wedge count");
  // Room for the full mesh known now, so that big arrays are not regrown split after split.
  mesh_.reserve(pm.full_vertex_count(), pm.full_face_count());
  if (fpw_ != 0) wedge_values_.reserve(pm.base.wedge_values.size() + pm.new_wedge_values.size());
}

void PmCursor::check_split(const VertexSplit& s) const {
  // Messages are built only on failure: this runs for every split.
  const auto fail = [&](const std::string& what) {
    throw_invalid("vsplit " + str(level_) + ": " + what);
  };
  const size_t n = vertex_count();
  if (s.vs >= n) fail("vs " + str(s.vs) + " out of range (" + str(n) + ")");
  if (s.vl != kNoId && s.vl >= n) fail("vl " + str(s.vl) + " out of range (" + str(n) + ")");
  if (s.vr != kNoId && s.vr >= n) fail("vr " + str(s.vr) + " out of range (" + str(n) + ")");
  if (!s.has_fl() && !s.has_fr()) fail("neither vl nor vr");
  if (s.vl == s.vr || s.vl == s.vs || s.vr == s.vs) fail("vs, vl and vr are not distinct");
  if (fpw_ == 0) return;

  const size_t wedges_after = wedge_count() + s.new_wedge_count;
  for (int k = 0; k < 6; ++k) {
    if (!(k < 3 ? s.has_fl() : s.has_fr())) continue;
    if (s.corner_wedges[k] >= wedges_after)
      fail("corner wedge " + str(s.corner_wedges[k]) + " out of range (" + str(wedges_after) + ")");
  }
  const size_t new_values_end = (wedges_after - pm_->base.wedge_count()) * fpw_;
  if (new_values_end > pm_->new_wedge_values.size()) fail("new wedge values missing");
  if (uint64_t(s.wedge_changes_begin) + s.wedge_changes_count > pm_->wedge_changes.size())
    fail("wedge changes out of range");
  for (uint32_t c = 0; c < s.wedge_changes_count; ++c) {
    const WedgeChange& change = pm_->wedge_changes[s.wedge_changes_begin + c];
    if (change.wedge >= wedge_count() ||
        uint64_t(change.values_offset) + 2 * fpw_ > pm_->wedge_change_values.size())
      fail("wedge change out of range");
  }
}

void PmCursor::apply_next() {
  if (level_ >= pm_->splits.size())
    throw_invalid("apply_next: already at the last level (" + str(level_) + ")");
  const VertexSplit& s = pm_->splits[level_];
  // Start loading what the next two splits will read while this one is applied.
  if (level_ + 2 < pm_->splits.size()) {
    const VertexSplit& later = pm_->splits[level_ + 2];
    mesh_.prefetch_vertex(later.vs);
    mesh_.prefetch_vertex(later.vl);
    mesh_.prefetch_vertex(later.vr);
  }
  if (level_ + 1 < pm_->splits.size()) mesh_.prefetch_faces_of(pm_->splits[level_ + 1].vs);
  check_split(s);
  const std::string problem = mesh_.find_fan(s, fan_);
  if (!problem.empty()) throw_invalid("vsplit " + str(level_) + " does not fit: " + problem);

  const VertexId vt = VertexId(vertex_count());
  mesh_.ensure_vertex(vt);
  mesh_.split(s, vt, fan_);
  mesh_.set_position(s.vs, s.vs_after);
  mesh_.set_position(vt, s.vt_after);
  if (fpw_ != 0) {
    const size_t first = (wedge_count() - pm_->base.wedge_count()) * fpw_;
    const auto values = pm_->new_wedge_values.begin();
    wedge_values_.insert(wedge_values_.end(), values + first,
                         values + first + s.new_wedge_count * fpw_);
    for (uint32_t c = 0; c < s.wedge_changes_count; ++c) {
      const WedgeChange& change = pm_->wedge_changes[s.wedge_changes_begin + c];
      const float* fine = pm_->wedge_change_values.data() + change.values_offset + fpw_;
      std::copy(fine, fine + fpw_, wedge_values_.begin() + change.wedge * fpw_);
    }
  }
  ++level_;
}

void PmCursor::undo_last() {
  if (level_ == 0) throw_invalid("undo_last: already at the base mesh");
  const VertexSplit& s = pm_->splits[level_ - 1];
  const VertexId vt = VertexId(vertex_count() - 1);
  // Start loading what the next two undos will read (as in apply_next).
  if (level_ >= 3) {
    const VertexSplit& later = pm_->splits[level_ - 3];
    mesh_.prefetch_vertex(later.vs);
    mesh_.prefetch_vertex(later.vl);
    mesh_.prefetch_vertex(later.vr);
    mesh_.prefetch_vertex(vt - 2);
  }
  if (level_ >= 2) mesh_.prefetch_faces_of(vt - 1);
  if (fpw_ != 0) {
    // Coarse values in reverse order: correct even if a split changed one wedge twice.
    for (uint32_t c = s.wedge_changes_count; c-- > 0;) {
      const WedgeChange& change = pm_->wedge_changes[s.wedge_changes_begin + c];
      const float* coarse = pm_->wedge_change_values.data() + change.values_offset;
      std::copy(coarse, coarse + fpw_, wedge_values_.begin() + change.wedge * fpw_);
    }
    wedge_values_.resize(wedge_values_.size() - s.new_wedge_count * fpw_);
  }
  mesh_.unsplit(s, vt);
  mesh_.set_position(s.vs, s.vs_before);
  mesh_.pop_vertex();
  --level_;
}

void PmCursor::go_to_level(size_t level) {
  if (level > pm_->splits.size())
    throw_invalid("level " + str(level) + " out of range (the PM has " + str(pm_->splits.size()) +
                  " splits)");
  while (level_ < level) apply_next();
  while (level_ > level) undo_last();
}

Mesh PmCursor::extract() const {
  return assemble_mesh(mesh_.positions(), mesh_.faces(), mesh_.face_wedges(), wedge_values_,
                       pm_->base.layout, pm_->base.positions_are_float);
}

}  // namespace parapm
