// Level selection by face count or error bound, and extraction of a level (levels.h).
// Selection scans the split records only (O(n), no mesh is built).
#include "pm/levels.h"

#include <cmath>
#include <string>

#include "pm/pm_cursor.h"
#include "util/error.h"

namespace parapm {

size_t face_count_at_level(const ProgressiveMesh& pm, size_t level) {
  if (level > pm.splits.size())
    throw_invalid("level " + std::to_string(level) + " out of range (the PM has " +
                  std::to_string(pm.splits.size()) + " splits)");
  size_t faces = pm.base.face_count();
  for (size_t i = 0; i < level; ++i) faces += size_t(pm.splits[i].new_faces());
  return faces;
}

size_t level_for_faces(const ProgressiveMesh& pm, size_t max_faces) {
  // Every split adds one or two faces, so the face count grows strictly with the level and
  // the first split that would overshoot ends the scan.
  size_t faces = pm.base.face_count();
  size_t level = 0;
  while (level < pm.splits.size()) {
    const size_t next = faces + size_t(pm.splits[level].new_faces());
    if (next > max_faces) break;
    faces = next;
    ++level;
  }
  return level;
}

size_t level_for_error(const ProgressiveMesh& pm, double max_error) {
  if (std::isnan(max_error)) throw_invalid("the maximum error is NaN");
  if (max_error < 0) return pm.splits.size();
  size_t level = 0;
  while (level < pm.splits.size() && double(pm.splits[level].error) > max_error) ++level;
  return level;
}

Mesh level_of_detail(const ProgressiveMesh& pm, size_t level) {
  if (level > pm.splits.size())
    throw_invalid("level " + std::to_string(level) + " out of range (the PM has " +
                  std::to_string(pm.splits.size()) + " splits)");
  PmCursor cursor(pm);
  cursor.go_to_level(level);
  return cursor.extract();
}

}  // namespace parapm
