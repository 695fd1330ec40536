// Small meshes drawn in code for unit tests (real meshes come from test_support.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

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

// A flat unit disc (z = 0) of `rings` rings of `segments` vertices around a centre: a round
// boundary of `segments` edges.
inline Mesh disc(int rings, int segments) {
  Mesh m;
  m.positions.push_back({0, 0, 0});
  for (int r = 1; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments, radius = double(r) / rings;
      m.positions.push_back({radius * std::cos(phi), radius * std::sin(phi), 0});
    }
  auto ring = [&](int r, int s) { return VertexId(1 + (r - 1) * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) m.faces.push_back({0, ring(1, s), ring(1, s + 1)});
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      m.faces.push_back({ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      m.faces.push_back({ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
  return m;
}

// `mesh` made double-sided: every face followed, after all of them, by its reverse (the same
// vertices in the opposite order), as exporters that write both sides of a thin part do.
inline Mesh double_sided(Mesh mesh) {
  const size_t faces = mesh.faces.size();
  for (size_t f = 0; f < faces; ++f) {
    const Triangle t = mesh.faces[f];
    mesh.faces.push_back({t[0], t[2], t[1]});
  }
  return mesh;
}

// A gently waving square sheet of n x n quads, made double-sided (the repair gives each inner
// vertex a front copy and a back copy, joined at the rim), beside a rippled sphere: the sheet
// simplifies only by seam collapses, cheap ones.
inline Mesh double_sided_sheet_beside_a_sphere(int n) {
  Mesh m = double_sided([n] {
    Mesh sheet;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        sheet.positions.push_back(
            {3.0 + 2.0 * i / n, 2.0 * j / n, 0.02 * std::sin(0.5 * i) * std::cos(0.4 * j)});
    auto at = [n](int i, int j) { return VertexId(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        sheet.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        sheet.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    return sheet;
  }());
  const Mesh sphere = uv_sphere(n, 2 * n, 0.1);
  const auto first = VertexId(m.positions.size());
  m.positions.insert(m.positions.end(), sphere.positions.begin(), sphere.positions.end());
  for (const Triangle& t : sphere.faces)
    m.faces.push_back({t[0] + first, t[1] + first, t[2] + first});
  return m;
}

// A UV sphere (uv_sphere) with back faces laid on it: the reverse (the same vertices in the
// opposite order) of every `every`-th face that shares no vertex with a face chosen before
// (stanford-dragon-res3 has about 160 such). With `open_hole`, the first chosen face is left
// out, so that its back face alone fills the hole.
inline Mesh uv_sphere_with_back_faces(int rings, int segments, int every, bool open_hole = false) {
  const Mesh sphere = uv_sphere(rings, segments);
  std::vector<bool> used(sphere.positions.size(), false);
  std::vector<Triangle> backs;
  for (size_t f = 0; f < sphere.faces.size(); f += size_t(every)) {
    const Triangle& t = sphere.faces[f];
    if (used[t[0]] || used[t[1]] || used[t[2]]) continue;
    for (VertexId v : t) used[v] = true;
    backs.push_back({t[0], t[2], t[1]});
  }
  Mesh m = sphere;
  if (open_hole)
    m.faces.erase(
        std::find(m.faces.begin(), m.faces.end(), Triangle{backs[0][0], backs[0][2], backs[0][1]}));
  m.faces.insert(m.faces.end(), backs.begin(), backs.end());
  return m;
}

// Numbers uniform in [lo, hi) from a seed (splitmix64): where the drawn scenes put their parts.
class SeededUniform {
 public:
  explicit SeededUniform(uint64_t seed) : state_(seed) {}
  double operator()(double lo, double hi) {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return lo + (hi - lo) * double(z ^ (z >> 31)) / 18446744073709551616.0;
  }

 private:
  uint64_t state_;
};

// An open ground square (two triangles, side 100, z = 0, boundary all round) carrying `boxes`
// closed boxes of 12 triangles, each a separate component 0.2-1 wide and 0.2-2 tall, placed by
// a seeded generator: a scene of many small parts on one large open one.
inline Mesh ground_with_boxes(int boxes, uint64_t seed = 1) {
  Mesh m;
  m.positions = {{0, 0, 0}, {100, 0, 0}, {100, 100, 0}, {0, 100, 0}};
  m.faces = {{0, 1, 2}, {0, 2, 3}};
  SeededUniform uniform(seed);
  for (int k = 0; k < boxes; ++k) {
    const double x = uniform(1, 98), y = uniform(1, 98), side = uniform(0.2, 1);
    const double height = uniform(0.2, 2);
    const auto o = VertexId(m.positions.size());
    for (double z : {0.0, height})
      for (const auto& [dx, dy] : {std::pair{0.0, 0.0}, {side, 0.0}, {side, side}, {0.0, side}})
        m.positions.push_back({x + dx, y + dy, z});
    const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                             {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    for (const auto& q : quads) {
      m.faces.push_back({o + q[0], o + q[1], o + q[2]});
      m.faces.push_back({o + q[0], o + q[2], o + q[3]});
    }
  }
  return m;
}

// An open ground square (side 100, z = 0, 8 x 8 quads, boundary all round) under `patches`
// small open parts: each a 2 x 2 grid of quads 0.2-1 wide, 0.1-2 above the ground and a
// separate component with a boundary all round, placed by a seeded generator (a scene of many
// small parts, as CAD assemblies and game levels are).
inline Mesh ground_with_patches(int patches, uint64_t seed = 1) {
  Mesh m;
  auto grid = [&m](int n, double x, double y, double side, double z, double tilt) {
    const auto o = VertexId(m.positions.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        m.positions.push_back({x + side * i / n, y + side * j / n, z + tilt * side * i / n});
    auto at = [&](int i, int j) { return o + VertexId(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        m.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        m.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  };
  grid(8, 0, 0, 100, 0, 0);
  SeededUniform uniform(seed);
  for (int k = 0; k < patches; ++k) {
    const double x = uniform(1, 98), y = uniform(1, 98), side = uniform(0.2, 1);
    const double z = uniform(0.1, 2), tilt = uniform(-0.5, 0.5);
    grid(2, x, y, side, z, tilt);
  }
  return m;
}

// `sheets` open sheets meeting along one line, as the pages of a book along its spine: the
// spine runs along x (`length` segments of 1, waving gently in y), and sheet k leaves it at
// the angle 2 pi k / sheets, `width` quads of 1 wide, bending as it goes. With three sheets or
// more, every spine edge is non-manifold (the repair splits each spine vertex into one copy
// per sheet).
inline Mesh book_of_sheets(int sheets, int length, int width) {
  Mesh m;
  auto spine = [](int i) { return Vec3{double(i), 0.2 * std::sin(0.7 * i), 0}; };
  for (int i = 0; i <= length; ++i) m.positions.push_back(spine(i));
  for (int k = 0; k < sheets; ++k) {
    const double angle = 2 * M_PI * k / sheets;
    const double c = std::cos(angle), s = std::sin(angle);
    const auto first = VertexId(m.positions.size());
    for (int j = 1; j <= width; ++j)
      for (int i = 0; i <= length; ++i) {
        const double bend = 0.3 * j * j / width;  // along the sheet's normal (-s, c)
        const Vec3 base = spine(i);
        m.positions.push_back({base[0], base[1] + j * c - bend * s, base[2] + j * s + bend * c});
      }
    auto at = [&](int i, int j) {
      return j == 0 ? VertexId(i) : first + VertexId((j - 1) * (length + 1) + i);
    };
    for (int j = 0; j < width; ++j)
      for (int i = 0; i < length; ++i) {
        m.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
        m.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  return m;
}

// A square plane (z = 0, n x n quads of 1, waving gently) with a fin standing on it along
// part of its middle row (columns first..last, `height` quads of 1 up, bending as it goes):
// the line is non-manifold (the plane's two sides and the fin meet there), and it ends inside
// the plane, whose sides join around its ends.
inline Mesh plane_with_fin(int n, int first, int last, int height) {
  Mesh m;
  auto plane = [&](int i, int j) {
    return Vec3{double(i), double(j), 0.05 * std::sin(0.9 * i) * std::cos(0.7 * j)};
  };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.positions.push_back(plane(i, j));
  auto at = [n](int i, int j) { return VertexId(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  const int row = n / 2;
  const auto fin = VertexId(m.positions.size());
  for (int k = 1; k <= height; ++k)
    for (int i = first; i <= last; ++i) {
      const Vec3 base = plane(i, row);
      m.positions.push_back({base[0], base[1] + 0.1 * k * k / height, base[2] + k});
    }
  auto up = [&](int i, int k) {
    return k == 0 ? at(i, row) : fin + VertexId((k - 1) * (last - first + 1) + (i - first));
  };
  for (int k = 0; k < height; ++k)
    for (int i = first; i < last; ++i) {
      m.faces.push_back({up(i, k), up(i + 1, k), up(i + 1, k + 1)});
      m.faces.push_back({up(i, k), up(i + 1, k + 1), up(i, k + 1)});
    }
  return m;
}

// A unit sphere (`rings` x `segments`, a multiple of `chart`) whose texture coordinates come
// in charts of chart x chart quads, each with wedges of its own: UV seams everywhere, as a
// texture atlas has them. Closed, genus 0.
inline Mesh sphere_with_uv_charts(int rings, int segments, int chart) {
  Mesh m = uv_sphere(rings, segments);
  m.layout.texcoords = true;
  // A wedge per (vertex, chart): the chart of a face is that of its quad.
  std::vector<std::array<WedgeId, 3>> corners;
  std::map<std::pair<VertexId, int>, WedgeId> wedges;
  auto wedge = [&](VertexId v, int chart_id, double u, double w) {
    const auto [it, added] = wedges.try_emplace({v, chart_id}, WedgeId(m.wedge_vertex.size()));
    if (added) {
      m.wedge_vertex.push_back(v);
      m.wedge_values.push_back(float(u));
      m.wedge_values.push_back(float(w));
    }
    return it->second;
  };
  for (const Triangle& t : m.faces) {
    // The face's quad: its ring band and segment, from its vertices' spherical angles.
    Vec3 c{0, 0, 0};
    for (VertexId v : t)
      for (int k = 0; k < 3; ++k) c[k] += m.positions[v][k] / 3;
    const double radius = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    const double theta = std::acos(std::clamp(c[2] / radius, -1.0, 1.0));
    double phi = std::atan2(c[1], c[0]);
    if (phi < 0) phi += 2 * M_PI;
    const int band = std::min(rings - 1, int(theta / M_PI * rings));
    const int segment = std::min(segments - 1, int(phi / (2 * M_PI) * segments));
    const int chart_id = (band / chart) * segments + segment / chart;
    std::array<WedgeId, 3> w{};
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = m.positions[t[k]];
      w[k] = wedge(t[k], chart_id, 0.5 + 0.5 * p[0], 0.5 + 0.5 * p[1]);
    }
    corners.push_back(w);
  }
  m.face_wedges = std::move(corners);
  return m;
}

}  // namespace parapm::testing
