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
  static Quadric from_plane(const Vec3& n, double d, double weight);

  Quadric& operator+=(const Quadric& q);
  Quadric& operator*=(double s);
  double evaluate(const Vec3& p) const;
  // The minimiser of Q, when A is well conditioned relative to its scale (|det A| above
  // relative_threshold x trace^3); false otherwise. A positive definite A (a caller that adds a
  // positive multiple of the identity) needs no threshold: 0.
  bool minimizer(Vec3& out, double relative_threshold = 1e-9) const;
};

}  // namespace parapm
