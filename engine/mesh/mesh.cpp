#include "mesh/mesh.h"

#include <algorithm>
#include <cmath>

namespace parapm {

double Box::diagonal() const {
  double sum = 0;
  for (int k = 0; k < 3; ++k) sum += (max[k] - min[k]) * (max[k] - min[k]);
  return std::sqrt(sum);
}

Box bounding_box(const Mesh& mesh) { return bounding_box(mesh.positions); }

Box bounding_box(const std::vector<Vec3>& positions) {
  Box box;
  if (positions.empty()) return box;
  box.min = box.max = positions[0];
  for (const Vec3& p : positions) {
    for (int k = 0; k < 3; ++k) {
      box.min[k] = std::min(box.min[k], p[k]);
      box.max[k] = std::max(box.max[k], p[k]);
    }
  }
  return box;
}

bool all_positions_are_float(const std::vector<Vec3>& positions) {
  for (const Vec3& p : positions)
    for (double c : p)
      if (round_to_float(c) != c) return false;
  return true;
}

}  // namespace parapm
