// Nearest triangle by a uniform grid searched in shells (see closest_point.h).
#include "measure/closest_point.h"

#include <algorithm>
#include <cmath>

#include "simplify/point_projection.h"
#include "simplify/vec_math.h"

namespace parapm {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double face_area(const Mesh& mesh, FaceId f) {
  const Triangle& t = mesh.faces[f];
  return 0.5 *
         length(triangle_normal(mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]));
}

Box triangle_box(const Mesh& mesh, FaceId f) {
  const Triangle& t = mesh.faces[f];
  Box box;
  box.min = box.max = mesh.positions[t[0]];
  for (int k = 1; k < 3; ++k)
    for (int a = 0; a < 3; ++a) {
      box.min[a] = std::min(box.min[a], mesh.positions[t[k]][a]);
      box.max[a] = std::max(box.max[a], mesh.positions[t[k]][a]);
    }
  return box;
}

}  // namespace

ClosestPointGrid::ClosestPointGrid(const Mesh& mesh, const std::vector<FaceId>& faces)
    : mesh_(mesh), visited_stamp_(mesh.face_count(), 0) {
  choose_cells(faces);
  fill_cells(faces);
}

void ClosestPointGrid::choose_cells(const std::vector<FaceId>& faces) {
  Box box = triangle_box(mesh_, faces.front());
  double area = 0;
  for (FaceId f : faces) {
    area += face_area(mesh_, f);
    const Box face_box = triangle_box(mesh_, f);
    for (int a = 0; a < 3; ++a) {
      box.min[a] = std::min(box.min[a], face_box.min[a]);
      box.max[a] = std::max(box.max[a], face_box.max[a]);
    }
  }
  origin_ = box.min;
  const double n = double(faces.size());
  const Vec3 extent = sub(box.max, box.min);
  // A flat or thin box has zero volume: the area term alone then sets the size.
  cell_size_ =
      std::max(std::sqrt(area / n), std::cbrt(extent[0] * extent[1] * extent[2] / (4 * n)));
  // Slivers in a long box can make the area term tiny: grow the cells until they are few.
  const double max_cells = 8 * n + 64;
  for (;;) {
    double cells = 1;
    for (int a = 0; a < 3; ++a) cells *= std::max(1.0, std::ceil(extent[a] / cell_size_));
    if (cells <= max_cells) break;
    cell_size_ *= 1.5;
  }
  for (int a = 0; a < 3; ++a) dims_[a] = int(std::max(1.0, std::ceil(extent[a] / cell_size_)));
}

void ClosestPointGrid::fill_cells(const std::vector<FaceId>& faces) {
  cell_start_.assign(size_t(dims_[0]) * size_t(dims_[1]) * size_t(dims_[2]) + 1, 0);
  for_each_overlapped_cell(faces, [&](FaceId, size_t cell) { ++cell_start_[cell + 1]; });
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_faces_.resize(cell_start_.back());
  std::vector<size_t> next_free(cell_start_.begin(), cell_start_.end() - 1);
  for_each_overlapped_cell(faces,
                           [&](FaceId f, size_t cell) { cell_faces_[next_free[cell]++] = f; });
}

template <class Visit>
void ClosestPointGrid::for_each_overlapped_cell(const std::vector<FaceId>& faces,
                                                Visit&& visit) const {
  for (FaceId f : faces) {
    const Box box = triangle_box(mesh_, f);
    const Cell lo = cell_of(box.min), hi = cell_of(box.max);
    for (int i = lo[0]; i <= hi[0]; ++i)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int k = lo[2]; k <= hi[2]; ++k) visit(f, cell_index(i, j, k));
  }
}

// The cell holding p, clamped to the grid (a query may lie outside the box). Clamped in
// double before the conversion, which would overflow for a far query.
ClosestPointGrid::Cell ClosestPointGrid::cell_of(const Vec3& p) const {
  Cell c;
  for (int a = 0; a < 3; ++a) {
    const double x = std::floor((p[a] - origin_[a]) / cell_size_);
    c[a] = int(std::clamp(x, 0.0, double(dims_[a] - 1)));
  }
  return c;
}

size_t ClosestPointGrid::cell_index(int i, int j, int k) const {
  return (size_t(i) * size_t(dims_[1]) + size_t(j)) * size_t(dims_[2]) + size_t(k);
}

double ClosestPointGrid::distance_sq_to_cell(const Vec3& p, const Cell& cell) const {
  double sum = 0;
  for (int a = 0; a < 3; ++a) {
    const double gap =
        std::max({cell_low(a, cell[a]) - p[a], p[a] - cell_low(a, cell[a] + 1), 0.0});
    sum += gap * gap;
  }
  return sum;
}

// A lower bound on the distance from p to any cell more than `radius` cells from `centre`
// (Chebyshev): such a cell lies past one side of the visited block, so p is at least as far
// from it as from that side's plane. Only sides with cells beyond them count (a query outside
// the grid is clamped to a border cell, beyond which there is nothing), so the bound is never
// negative. Infinity when the block is the whole grid.
double ClosestPointGrid::distance_beyond_block(const Vec3& p, const Cell& centre,
                                               int radius) const {
  double bound = kInfinity;
  for (int a = 0; a < 3; ++a) {
    if (centre[a] - radius > 0) bound = std::min(bound, p[a] - cell_low(a, centre[a] - radius));
    if (centre[a] + radius < dims_[a] - 1)
      bound = std::min(bound, cell_low(a, centre[a] + radius + 1) - p[a]);
  }
  return std::max(bound, 0.0);
}

// The cells exactly `radius` cells from `centre`: the surface of a cube of cells, clipped to
// the grid.
void ClosestPointGrid::visit_shell(const Vec3& p, const Cell& centre, int radius,
                                   SurfacePoint& best) {
  const auto first = [&](int a) { return std::max(0, centre[a] - radius); };
  const auto last = [&](int a) { return std::min(dims_[a] - 1, centre[a] + radius); };
  for (int i = first(0); i <= last(0); ++i)
    for (int j = first(1); j <= last(1); ++j) {
      if (std::abs(i - centre[0]) == radius || std::abs(j - centre[1]) == radius) {
        for (int k = first(2); k <= last(2); ++k) visit_cell(p, {i, j, k}, best);
      } else {
        // Strictly inside the ring in i and j: only the two caps in k are on the shell.
        if (centre[2] - radius >= 0) visit_cell(p, {i, j, centre[2] - radius}, best);
        if (centre[2] + radius < dims_[2]) visit_cell(p, {i, j, centre[2] + radius}, best);
      }
    }
}

void ClosestPointGrid::visit_cell(const Vec3& p, const Cell& cell, SurfacePoint& best) {
  // A cell no nearer than the best face cannot hold a strictly nearer one.
  if (distance_sq_to_cell(p, cell) >= best.distance_sq) return;
  const size_t c = cell_index(cell[0], cell[1], cell[2]);
  for (size_t e = cell_start_[c]; e < cell_start_[c + 1]; ++e) {
    const FaceId f = cell_faces_[e];
    if (visited_stamp_[f] == stamp_) continue;  // listed in several cells
    visited_stamp_[f] = stamp_;
    const Triangle& t = mesh_.faces[f];
    const Projection projection =
        project_on_triangle(p, mesh_.positions[t[0]], mesh_.positions[t[1]], mesh_.positions[t[2]]);
    if (projection.distance_sq < best.distance_sq)
      best = {f, projection.bary, projection.distance_sq};
  }
}

// The visited stamps are cleared only when the 32-bit query counter wraps.
void ClosestPointGrid::next_stamp() {
  if (++stamp_ == 0) {
    std::fill(visited_stamp_.begin(), visited_stamp_.end(), 0);
    stamp_ = 1;
  }
}

SurfacePoint ClosestPointGrid::closest_point(const Vec3& p) {
  next_stamp();
  SurfacePoint best;
  const Cell centre = cell_of(p);
  for (int radius = 0;; ++radius) {
    if (radius > 0) {
      // Every cell not yet visited is at least this far: nothing there can beat `best`.
      const double bound = distance_beyond_block(p, centre, radius - 1);
      if (bound == kInfinity || best.distance_sq <= bound * bound) return best;
    }
    visit_shell(p, centre, radius, best);
  }
}

}  // namespace parapm
