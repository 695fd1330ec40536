// parapm-render MESH... -o OUT.png: draws meshes side by side, from one camera, into a PNG,
// so that levels of detail can be looked at next to their original without a viewer (the
// energy issue's "colours and UV seams visibly right" check). Orthographic, z-buffered,
// flat-lit; a face's colour interpolates its corners' wedges: vertex colours when the mesh
// has them, else texture coordinates as a checkerboard tinted by (u, v), so that a seam torn
// or smeared by simplification shows as a broken pattern; else grey.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "io/mesh_io.h"
#include "mesh/mesh.h"
#include "png_writer.h"
#include "simplify/vec_math.h"
#include "util/error.h"

namespace parapm {
namespace {

using Rgb = std::array<double, 3>;

struct Camera {
  Vec3 centre{}, right{}, up{}, toward{};  // toward: from the scene to the viewer
  double scale = 1;                        // pixels per model unit
  int size = 512;
};

Vec3 normalized(const Vec3& v) {
  const double l = length(v);
  return l > 0 ? scale(v, 1 / l) : v;
}

Camera frame(const Mesh& mesh, double azimuth_deg, double elevation_deg, int size) {
  const Box box = bounding_box(mesh);
  Camera c;
  c.size = size;
  for (int k = 0; k < 3; ++k) c.centre[k] = 0.5 * (box.min[k] + box.max[k]);
  const double az = azimuth_deg * M_PI / 180, el = elevation_deg * M_PI / 180;
  c.toward = {std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
  c.right = normalized(cross({0, 1, 0}, c.toward));
  c.up = cross(c.toward, c.right);
  // Fit the mesh's silhouette box, not its bounding sphere, to the tile.
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const Vec3& p : mesh.positions) {
    const Vec3 d = sub(p, c.centre);
    const double s[2] = {dot(d, c.right), dot(d, c.up)};
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], s[k]), hi[k] = std::max(hi[k], s[k]);
  }
  if (mesh.positions.empty()) return c;
  for (int k = 0; k < 3; ++k)
    c.centre[k] += 0.5 * (lo[0] + hi[0]) * c.right[k] + 0.5 * (lo[1] + hi[1]) * c.up[k];
  c.scale = 0.92 * size / std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-30});
  return c;
}

// The colour a corner's wedge gives, before lighting.
Rgb wedge_colour(const Mesh& mesh, WedgeId w) {
  const float* value = mesh.wedge(w);
  if (mesh.layout.colors) {
    const float* c = value + mesh.layout.color_offset();
    return {c[0], c[1], c[2]};
  }
  const float* uv = value + mesh.layout.texcoord_offset();
  return {uv[0], uv[1], 0};  // made a checkerboard per pixel (shade_uv)
}

Rgb shade_uv(const Rgb& uv) {
  const int checker = (int(std::floor(uv[0] * 16)) + int(std::floor(uv[1] * 16))) & 1;
  const double base = checker ? 0.95 : 0.35;
  return {base * (0.5 + 0.5 * std::clamp(uv[0], 0.0, 1.0)),
          base * (0.5 + 0.5 * std::clamp(uv[1], 0.0, 1.0)), base * 0.6};
}

// Draws `mesh` into the tile whose left edge is at pixel column x0.
void draw(const Mesh& mesh, const Camera& cam, int x0, int width, std::vector<double>& depth,
          std::vector<uint8_t>& rgb) {
  const bool colours = mesh.layout.colors && !mesh.face_wedges.empty();
  const bool uvs = !colours && mesh.layout.texcoords && !mesh.face_wedges.empty();
  const Vec3 light = normalized({cam.toward[0] + 0.3, cam.toward[1] + 0.5, cam.toward[2]});
  std::vector<std::array<double, 3>> screen(mesh.vertex_count());
  for (VertexId v = 0; v < mesh.vertex_count(); ++v) {
    const Vec3 d = sub(mesh.positions[v], cam.centre);
    screen[v] = {x0 + 0.5 * cam.size + cam.scale * dot(d, cam.right),
                 0.5 * cam.size - cam.scale * dot(d, cam.up), dot(d, cam.toward)};
  }
  for (FaceId f = 0; f < mesh.face_count(); ++f) {
    const Triangle& t = mesh.faces[f];
    const auto &a = screen[t[0]], &b = screen[t[1]], &c = screen[t[2]];
    const double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (area == 0) continue;
    const Vec3 n = normalized(cross(sub(mesh.positions[t[1]], mesh.positions[t[0]]),
                                    sub(mesh.positions[t[2]], mesh.positions[t[0]])));
    const double light_factor = 0.35 + 0.65 * std::abs(dot(n, light));
    std::array<Rgb, 3> corner{};
    for (int k = 0; k < 3; ++k)
      corner[k] =
          (colours || uvs) ? wedge_colour(mesh, mesh.face_wedges[f][k]) : Rgb{0.8, 0.8, 0.8};
    const int xmin = std::max(x0, int(std::floor(std::min({a[0], b[0], c[0]}))));
    const int xmax = std::min(x0 + cam.size - 1, int(std::ceil(std::max({a[0], b[0], c[0]}))));
    const int ymin = std::max(0, int(std::floor(std::min({a[1], b[1], c[1]}))));
    const int ymax = std::min(cam.size - 1, int(std::ceil(std::max({a[1], b[1], c[1]}))));
    for (int y = ymin; y <= ymax; ++y)
      for (int x = xmin; x <= xmax; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
        const double w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
        const double w2 = 1 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double z = w0 * a[2] + w1 * b[2] + w2 * c[2];
        const size_t pixel = size_t(y) * size_t(width) + size_t(x);
        if (z <= depth[pixel]) continue;
        depth[pixel] = z;
        Rgb colour{};
        for (int k = 0; k < 3; ++k)
          colour[k] = w0 * corner[0][k] + w1 * corner[1][k] + w2 * corner[2][k];
        if (uvs) colour = shade_uv(colour);
        for (int k = 0; k < 3; ++k)
          rgb[pixel * 3 + size_t(k)] =
              uint8_t(std::lround(255 * std::clamp(colour[k] * light_factor, 0.0, 1.0)));
      }
  }
}

}  // namespace
}  // namespace parapm

int main(int argc, char** argv) {
  using namespace parapm;
  CLI::App app{
      "Draws meshes side by side from one camera (framed on the first) into a PNG: vertex "
      "colours if present, else texture coordinates as a checkerboard, else grey."};
  std::vector<std::string> inputs;
  std::string output;
  int size = 512;
  double azimuth = 30, elevation = 20;
  app.add_option("meshes", inputs, "Meshes (OBJ, PLY, OFF, STL; optionally .gz)")->required();
  app.add_option("-o,--output", output, "The PNG to write")->required();
  app.add_option("--size", size, "Pixels of each tile's side")
      ->check(CLI::Range(16, 4096))
      ->capture_default_str();
  app.add_option("--azimuth", azimuth, "Camera angle around the vertical axis, degrees")
      ->capture_default_str();
  app.add_option("--elevation", elevation, "Camera angle above the horizon, degrees")
      ->check(CLI::Range(-89.0, 89.0))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    std::vector<Mesh> meshes;
    for (const std::string& path : inputs) meshes.push_back(read_mesh(path));
    const Camera cam = frame(meshes.front(), azimuth, elevation, size);
    const int width = size * int(meshes.size());
    std::vector<uint8_t> rgb(size_t(width) * size_t(size) * 3, 255);
    std::vector<double> depth(size_t(width) * size_t(size),
                              -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < meshes.size(); ++i)
      draw(meshes[i], cam, int(i) * size, width, depth, rgb);
    write_png(output, width, size, rgb);
    std::printf("wrote %s (%d x %d)\n", output.c_str(), width, size);
  } catch (const Error& e) {
    std::fprintf(stderr, "parapm-render: %s\n", e.what());
    return 2;
  }
  return 0;
}
