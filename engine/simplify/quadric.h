// Quadric error metric (Garland & Heckbert, "Surface Simplification Using Quadric Error
// Metrics", SIGGRAPH 97): the squared distance to a set of planes, as a symmetric 4x4 form.
//
// Plane quadrics are weighted by face area, so a quadric's value has units of area x
// length^2; `weight` accumulates the areas, so value / weight is a mean squared distance in
// model units (what the PM records as the error of a collapse, after a square root).
#pragma once

#include <array>

#include "mesh/mesh.h"

namespace parapm {

struct Quadric {
  // Upper triangle of A (3x3), then b (3), then c: Q(p) = p'Ap + 2b'p + c.
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0;
  double b0 = 0, b1 = 0, b2 = 0;
  double c = 0;
  double weight = 0;

  // The plane n.p + d = 0 (n unit length), weighted.
  static Quadric from_plane(const Vec3& n, double d, double weight) {
    Quadric q;
    q.a00 = weight * n[0] * n[0];
    q.a01 = weight * n[0] * n[1];
    q.a02 = weight * n[0] * n[2];
    q.a11 = weight * n[1] * n[1];
    q.a12 = weight * n[1] * n[2];
    q.a22 = weight * n[2] * n[2];
    q.b0 = weight * n[0] * d;
    q.b1 = weight * n[1] * d;
    q.b2 = weight * n[2] * d;
    q.c = weight * d * d;
    q.weight = weight;
    return q;
  }

  // Inline (with from_plane and evaluate): the costings' inner loops sum thousands of these.
  Quadric& operator+=(const Quadric& q) {
    a00 += q.a00, a01 += q.a01, a02 += q.a02, a11 += q.a11, a12 += q.a12, a22 += q.a22;
    b0 += q.b0, b1 += q.b1, b2 += q.b2;
    c += q.c;
    weight += q.weight;
    return *this;
  }
  Quadric& operator-=(const Quadric& q) {
    a00 -= q.a00, a01 -= q.a01, a02 -= q.a02, a11 -= q.a11, a12 -= q.a12, a22 -= q.a22;
    b0 -= q.b0, b1 -= q.b1, b2 -= q.b2;
    c -= q.c;
    weight -= q.weight;
    return *this;
  }
  Quadric& operator*=(double s);
  double evaluate(const Vec3& p) const {
    const double x = p[0], y = p[1], z = p[2];
    return a00 * x * x + 2 * a01 * x * y + 2 * a02 * x * z + a11 * y * y + 2 * a12 * y * z +
           a22 * z * z + 2 * (b0 * x + b1 * y + b2 * z) + c;
  }
  // The minimiser of Q, when A is well conditioned relative to its scale (|det A| above
  // relative_threshold x trace^3); false otherwise. A positive definite A (a caller that adds a
  // positive multiple of the identity) needs no threshold: 0.
  bool minimizer(Vec3& out, double relative_threshold = 1e-9) const;
  // The least value of Q over all points, 0 or more, for any A (a flat or creased one too):
  // Q(about) less what a move from `about` saves along A's eigenvectors, over those whose
  // eigenvalue is above 1e-12 x the largest (along the others Q is flat up to rounding). A
  // lower bound of Q anywhere; `about` near the points that matter keeps its rounding small.
  double least_value(const Vec3& about) const;
};

}  // namespace parapm
