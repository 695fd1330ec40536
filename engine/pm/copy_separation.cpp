#include "pm/copy_separation.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "pm/levels.h"
#include "util/error.h"

namespace parapm {

CopySeparation copy_separation(const ProgressiveMesh& pm, size_t level) {
  if (level > pm.splits.size())
    throw_invalid("level " + std::to_string(level) + " exceeds the PM's " +
                  std::to_string(pm.splits.size()) + " splits");
  CopySeparation out;
  out.pairs = pm.vertex_copies.size();
  if (pm.vertex_copies.empty()) return out;
  const Mesh mesh = level_of_detail(pm, level);
  const size_t present = pm.base.vertex_count() + level;
  if (mesh.positions.size() < present)
    throw Error(ErrorCode::kInternal, "a level's mesh holds fewer vertices than it has");
  // Split i's vs exists before split i, so the stand-in chain only goes down in id.
  std::vector<VertexId> stand_in(pm.full_vertex_count());
  for (VertexId v = 0; v < stand_in.size(); ++v)
    stand_in[v] = v < present ? v : stand_in[pm.splits[v - pm.base.vertex_count()].vs];
  double sum = 0;
  for (const auto& [copy, original] : pm.vertex_copies) {
    const Vec3& a = mesh.positions[stand_in[copy]];
    const Vec3& b = mesh.positions[stand_in[original]];
    const double d = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                               (a[2] - b[2]) * (a[2] - b[2]));
    if (d > 0) ++out.parted;
    out.max = std::max(out.max, d);
    sum += d;
  }
  out.mean = sum / double(out.pairs);
  return out;
}

}  // namespace parapm
