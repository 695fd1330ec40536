// Lindstrom and Turk's placement constraints ("Fast and memory efficient polygonal
// simplification", 98), for the quadric's vertex placement: linear equations on the position v
// of the vertex a collapse of {a, b} leaves, each keeping something the star had before it.
// - Volume: the signed volume the star's faces enclose (with any point) stays: without it a
//   coarse level shrinks where the surface curves, each collapse cutting a little off its
//   convex side.
// - Border: the area vector swept by the border edges at a and b stays (two equations, across
//   the border's direction): without it a flat part's outline shrinks the same way.
// The quadric is then minimised on the points that meet them (on the one point, for three).
//
// Every sum runs in the order of the positions it reads, not of ids or face lists: a subset
// job, whose ids and lists differ from the whole mesh's, gets the same bits.
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "simplify/collapse_mesh.h"
#include "simplify/quadric.h"

namespace parapm {

// Up to three independent equations row.(v - origin) = rhs, rows orthonormal.
class PlacementConstraints {
 public:
  explicit PlacementConstraints(const Vec3& origin) : origin_(origin) {}
  // Adds n.(v - origin) = d unless n lies within a degree of the rows' span (Lindstrom-Turk's
  // alpha-compatibility) or is zero.
  void require(Vec3 n, double d);
  // The two equations across e1 of (v - origin) x e1 = e2 (e1 not zero).
  void require_cross(const Vec3& e1, const Vec3& e2);
  int count() const { return count_; }
  // The minimiser of q among the points that meet every row; false where q has none there (no
  // row, or q flat along a direction the rows leave free).
  bool minimize(const Quadric& q, Vec3& out) const;

 private:
  Vec3 origin_;
  std::array<Vec3, 3> rows_{};
  std::array<double, 3> rhs_{};
  int count_ = 0;
};

// The working memory of the star's sums (one per module, reused).
struct StarTermsScratch {
  struct FaceTerm {
    Vec3 p1, p2, end;  // the corners after the moving end, and the end
    bool vanishes;     // the face holds both ends
  };
  std::vector<FaceTerm> faces;
  // The order the faces are summed in: each one's p1[0] and index, sorted (a 16-byte key moves
  // faster than a term; ties on p1[0] are broken by the terms).
  std::vector<std::pair<double, uint32_t>> order;
  std::vector<std::pair<VertexId, VertexId>> border;  // directed as their faces hold them
  std::vector<std::pair<VertexId, VertexId>> fan;     // a border end's faces: (next, previous)
  // Sums over the faces around one vertex v, each face (v, p1, p2) as its corners follow v:
  // cross = sum of (p1 - v) x (p2 - v), turn = sum of p2 - p1, planes = the faces' planes
  // weighted by area (when asked for).
  struct VertexStar {
    Vec3 cross{}, turn{};
    Quadric planes;
  };
  // The sums of vertices of many faces (a fan's hub in a CAD part: hundreds), direct-mapped by
  // vertex id and kept while the vertex's star version stays.
  struct KeptStar {
    uint64_t mesh = 0;  // CollapseMesh::identity; 0: empty
    VertexId v = kNoId;
    uint32_t version = 0;
    bool planes = false;
    VertexStar sums;
  };
  std::vector<KeptStar> kept;
};

// The volume equation of collapsing {a, b}: g.(v - origin) = h, six times the volume the star's
// faces enclose with origin after and before (a face holding both ends vanishes). With
// `planes`: the planes of the star's faces that stay, before the collapse, each weighted by its
// area, added to it.
void star_volume(const CollapseMesh& mesh, VertexId a, VertexId b, const Vec3& origin,
                 StarTermsScratch& scratch, Vec3& g, double& h, Quadric* planes = nullptr);

// The border equations of collapsing {a, b}: (v - origin) x e1 = e2, e2 the sum of
// (p - origin) x (q - origin) over the border edges (p, q) at a and b before, and the same sum
// after is (v - origin) x e1. False when neither end has a border edge.
bool star_border(const CollapseMesh& mesh, VertexId a, VertexId b, const Vec3& origin,
                 StarTermsScratch& scratch, Vec3& e1, Vec3& e2);

}  // namespace parapm
