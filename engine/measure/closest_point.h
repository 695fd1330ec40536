// Exact closest points on a triangle mesh, for many queries: a uniform grid of cells over the
// faces, searched in growing shells of cells (Chebyshev rings) around the query's cell until
// the nearest unvisited cell is farther than the best face found. Exact, not approximate: the
// answer is the minimum of project_on_triangle over every listed face (Ericson, Real-Time
// Collision Detection, 5.1.5 and 7.1).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

// A point on a mesh: a face and barycentric coordinates on its corners (sum 1).
struct SurfacePoint {
  FaceId face = kNoId;
  std::array<double, 3> bary{};
  double distance_sq = std::numeric_limits<double>::infinity();  // to the query, model units^2
};

// Cells of side max(sqrt(area / faces), cbrt(volume / (4 faces))): about one face per
// occupied cell on a surface, and ~4 cells per face at most in the whole box; each face is
// listed in every cell its bounding box overlaps. Meant for surfaces whose triangles are of
// similar size (what simplifiers produce): tiny triangles clustered in a huge box crowd into
// few cells and make queries slow, never wrong.
//
// Memory: 8 bytes per cell, 4 per listing (a few per face), 4 per face of the mesh.
// Not thread-safe (a query stamps the faces it has visited); the mesh must outlive the grid.
class ClosestPointGrid {
 public:
  // `faces`: the faces to search, none empty of area (zero-area faces are the caller's to
  // skip); all ids and corners must be in range. `faces` must not be empty.
  ClosestPointGrid(const Mesh& mesh, const std::vector<FaceId>& faces);

  // The closest point of the listed faces to p, anywhere in space. Ties go to the first face
  // met in a fixed visiting order, so the answer is deterministic.
  SurfacePoint closest_point(const Vec3& p);

 private:
  using Cell = std::array<int, 3>;

  void choose_cells(const std::vector<FaceId>& faces);
  void fill_cells(const std::vector<FaceId>& faces);
  template <class Visit>
  void for_each_overlapped_cell(const std::vector<FaceId>& faces, Visit&& visit) const;
  Cell cell_of(const Vec3& p) const;
  size_t cell_index(int i, int j, int k) const;
  double cell_low(int axis, int index) const { return origin_[axis] + index * cell_size_; }
  double distance_sq_to_cell(const Vec3& p, const Cell& cell) const;
  double distance_beyond_block(const Vec3& p, const Cell& centre, int radius) const;
  void visit_shell(const Vec3& p, const Cell& centre, int radius, SurfacePoint& best);
  void visit_cell(const Vec3& p, const Cell& cell, SurfacePoint& best);
  void next_stamp();

  const Mesh& mesh_;
  Vec3 origin_{};
  double cell_size_ = 1;
  Cell dims_{1, 1, 1};
  // Compressed rows: the faces of cell c are cell_faces_[cell_start_[c] .. cell_start_[c + 1]).
  std::vector<size_t> cell_start_;
  std::vector<FaceId> cell_faces_;
  std::vector<uint32_t> visited_stamp_;  // per face of the mesh: the last query that projected it
  uint32_t stamp_ = 0;
};

}  // namespace parapm
