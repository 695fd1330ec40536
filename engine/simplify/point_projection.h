// Closest points on triangles and segments, with the barycentric coordinates the energy's
// least-squares step needs (Hoppe 93 section 4: a point's projection is held as barycentric
// coordinates on the face it projects onto).
#pragma once

#include <array>
#include <limits>

#include "simplify/vec_math.h"

namespace parapm {

struct Projection {
  std::array<double, 3> bary{};  // of the closest point, on the triangle's corners (sum 1)
  double distance_sq = 0;
};

struct SegmentProjection {
  double t = 0;  // closest point a + t (b - a), t in [0, 1]
  double distance_sq = 0;
};

inline SegmentProjection project_on_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = sub(b, a);
  const double len_sq = dot(ab, ab);
  SegmentProjection r;
  r.t = len_sq > 0 ? dot(sub(p, a), ab) / len_sq : 0;
  r.t = r.t < 0 ? 0 : r.t > 1 ? 1 : r.t;
  const Vec3 d = sub(p, add(a, scale(ab, r.t)));
  r.distance_sq = dot(d, d);
  return r;
}

// The point of triangle (a, b, c) closest to p (Ericson, Real-Time Collision Detection,
// 5.1.5: Voronoi regions of the corners and edges, then the interior). Degenerate triangles
// are handled: the answer is then a closest point on an edge or a corner. Inline: it is the
// energy metric's innermost loop.
inline Projection project_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  Projection r;
  auto finish = [&](double u, double v, double w) {
    r.bary = {u, v, w};
    const Vec3 q = {u * a[0] + v * b[0] + w * c[0], u * a[1] + v * b[1] + w * c[1],
                    u * a[2] + v * b[2] + w * c[2]};
    const Vec3 d = sub(p, q);
    r.distance_sq = dot(d, d);
    return r;
  };
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return finish(1, 0, 0);
  const Vec3 bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return finish(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double denom = d1 - d3;
    const double v = denom > 0 ? d1 / denom : 0;
    return finish(1 - v, v, 0);
  }
  const Vec3 cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return finish(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double denom = d2 - d6;
    const double w = denom > 0 ? d2 / denom : 0;
    return finish(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double denom = (d4 - d3) + (d5 - d6);
    const double w = denom > 0 ? (d4 - d3) / denom : 0;
    return finish(0, 1 - w, w);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) {
    // Degenerate triangle (all regions above failed by rounding): best of its three edges.
    Projection best;
    best.distance_sq = -1;
    const std::array<std::array<int, 2>, 3> edges{{{0, 1}, {1, 2}, {2, 0}}};
    const std::array<const Vec3*, 3> corners{&a, &b, &c};
    for (const auto& e : edges) {
      const SegmentProjection s = project_on_segment(p, *corners[e[0]], *corners[e[1]]);
      if (best.distance_sq < 0 || s.distance_sq < best.distance_sq) {
        best.bary = {0, 0, 0};
        best.bary[e[0]] = 1 - s.t;
        best.bary[e[1]] = s.t;
        best.distance_sq = s.distance_sq;
      }
    }
    return best;
  }
  const double v = vb / sum, w = vc / sum;
  return finish(1 - v - w, v, w);
}

// A triangle prepared for many projections: a point whose plane projection falls inside (the
// common case) costs two dot products and a few multiplies; outside, the closest point is on
// an edge across which the projection lies (a negative barycentric coordinate), so at most
// two segments are tried. Degenerate triangles go to project_on_triangle. Always inlined: it
// is the innermost loop of the energy, and the compiler stops inlining it once it has a few
// callers.
class PreparedTriangle {
 public:
  PreparedTriangle() = default;
  PreparedTriangle(const Vec3& a, const Vec3& b, const Vec3& c) { reset(a, b, c); }
  // In place: the energy re-prepares a star's faces for every position it tries.
  [[gnu::always_inline]] void reset(const Vec3& a, const Vec3& b, const Vec3& c) {
    a_ = a;
    b_ = b;
    c_ = c;
    e1_ = sub(b, a);
    e2_ = sub(c, a);
    d11_ = dot(e1_, e1_);
    d12_ = dot(e1_, e2_);
    d22_ = dot(e2_, e2_);
    normal_ = cross(e1_, e2_);
    const double det = d11_ * d22_ - d12_ * d12_;  // = |normal|^2
    fast_ = det > 1e-12 * d11_ * d22_ && det > 0;
    inverse_det_ = fast_ ? 1.0 / det : 0.0;
  }
  [[gnu::always_inline]] Projection project(const Vec3& p) const {
    if (fast_) {
      const Vec3 w = sub(p, a_);
      const double t1 = dot(e1_, w), t2 = dot(e2_, w);
      const double beta = (d22_ * t1 - d12_ * t2) * inverse_det_;
      const double gamma = (d11_ * t2 - d12_ * t1) * inverse_det_;
      const double alpha = 1 - beta - gamma;
      if (beta >= 0 && gamma >= 0 && alpha >= 0) {
        const double h = dot(normal_, w);
        return {{alpha, beta, gamma}, h * h * inverse_det_};
      }
      Projection best;
      best.distance_sq = std::numeric_limits<double>::infinity();
      if (gamma < 0) {  // across edge a-b
        const double t = clamp01(t1 / d11_);
        consider(best, sub(w, scale(e1_, t)), {1 - t, t, 0});
      }
      if (beta < 0) {  // across edge a-c
        const double t = clamp01(t2 / d22_);
        consider(best, sub(w, scale(e2_, t)), {1 - t, 0, t});
      }
      if (alpha < 0) {  // across edge b-c
        const Vec3 e3 = sub(c_, b_);
        const Vec3 wb = sub(p, b_);
        const double t = clamp01(dot(e3, wb) / dot(e3, e3));
        consider(best, sub(wb, scale(e3, t)), {0, 1 - t, t});
      }
      return best;
    }
    return project_on_triangle(p, a_, b_, c_);
  }
  // A lower bound of project(p).distance_sq: the squared distance to the triangle's plane
  // (0 for a degenerate triangle, which has none). Equal to it where p projects inside.
  [[gnu::always_inline]] double plane_distance_sq(const Vec3& p) const {
    const double h = dot(normal_, sub(p, a_));
    return h * h * inverse_det_;
  }

 private:
  static double clamp01(double t) { return t < 0 ? 0 : t > 1 ? 1 : t; }
  static void consider(Projection& best, const Vec3& offset, const std::array<double, 3>& bary) {
    const double d = dot(offset, offset);
    if (d < best.distance_sq) best = {bary, d};
  }

  Vec3 a_{}, b_{}, c_{}, e1_{}, e2_{}, normal_{};
  double d11_ = 0, d12_ = 0, d22_ = 0, inverse_det_ = 0;
  bool fast_ = false;
};

}  // namespace parapm
