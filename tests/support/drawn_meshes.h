// Small meshes drawn in code for unit tests (real meshes come from test_support.h).
#pragma once

#include <cmath>

#include "mesh/mesh.h"

namespace parapm::testing {

// A UV sphere: closed, genus 0, `rings` x `segments`. A non-zero `ripple` modulates the
// radius (1 + ripple sin(5 phi) sin(3 theta)), for a surface with curvature to measure.
inline Mesh uv_sphere(int rings, int segments, double ripple = 0) {
  Mesh m;
  m.positions.push_back({0, 0, 1});
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      const double radius = 1 + ripple * std::sin(5 * phi) * std::sin(3 * theta);
      m.positions.push_back({radius * std::sin(theta) * std::cos(phi),
                             radius * std::sin(theta) * std::sin(phi), std::cos(theta)});
    }
  }
  m.positions.push_back({0, 0, -1});
  const auto south = VertexId(m.positions.size() - 1);
  auto ring = [&](int r, int s) { return VertexId(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) m.faces.push_back({0, ring(1, s), ring(1, s + 1)});
  for (int r = 1; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      m.faces.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      m.faces.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
  for (int s = 0; s < segments; ++s)
    m.faces.push_back({south, ring(rings - 1, s + 1), ring(rings - 1, s)});
  return m;
}

}  // namespace parapm::testing
