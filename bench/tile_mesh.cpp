// parapm-tile IN OUT --grid NxM: a larger test mesh made of N x M copies of IN side by side
// (copies along x, rows along y, a gap of --gap times the mesh's extent between them), with
// its attributes, for the parallel build's scaling benchmarks (bench/scaling.sh). Each copy
// keeps IN's topology; coordinates are rounded to float32 when IN's are float32, so that the
// PM stores them exactly as it stores IN's. Exit status: 0 success, 2 an error (one line on
// stderr).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>

#include "io/mesh_io.h"
#include "mesh/mesh.h"
#include "util/error.h"

namespace {

struct Grid {
  unsigned columns = 2;
  unsigned rows = 2;
};

Grid parse_grid(const std::string& text) {
  Grid grid;
  char x = 0;
  char rest = 0;
  if (std::sscanf(text.c_str(), "%u%c%u%c", &grid.columns, &x, &grid.rows, &rest) != 3 ||
      (x != 'x' && x != 'X') || grid.columns == 0 || grid.rows == 0 ||
      uint64_t(grid.columns) * grid.rows > 4096)
    throw parapm::Error(parapm::ErrorCode::kInvalidInput,
                        "--grid: '" + text + "' is not NxM with 1 <= N x M <= 4096");
  return grid;
}

parapm::Mesh tiled(const parapm::Mesh& in, const Grid& grid, double gap) {
  using namespace parapm;
  const Box box = bounding_box(in);
  const double step_x = (box.max[0] - box.min[0]) * (1 + gap);
  const double step_y = (box.max[1] - box.min[1]) * (1 + gap);
  const uint64_t copies = uint64_t(grid.columns) * grid.rows;
  if (copies * in.vertex_count() >= kNoId || copies * in.face_count() >= kNoId ||
      copies * in.wedge_count() >= kNoId)
    throw Error(ErrorCode::kInvalidInput, "--grid: the tiled mesh would need 32-bit ids");
  Mesh out;
  out.layout = in.layout;
  const auto vertices = uint32_t(in.vertex_count());
  const auto wedges = uint32_t(in.wedge_count());
  for (unsigned row = 0; row < grid.rows; ++row)
    for (unsigned column = 0; column < grid.columns; ++column) {
      const auto copy = uint32_t(row * grid.columns + column);
      for (Vec3 p : in.positions) {
        p[0] += column * step_x;
        p[1] += row * step_y;
        if (in.positions_are_float)
          for (double& c : p) c = round_to_float(c);
        out.positions.push_back(p);
      }
      for (const Triangle& t : in.faces)
        out.faces.push_back(
            {t[0] + copy * vertices, t[1] + copy * vertices, t[2] + copy * vertices});
      for (VertexId v : in.wedge_vertex) out.wedge_vertex.push_back(v + copy * vertices);
      out.wedge_values.insert(out.wedge_values.end(), in.wedge_values.begin(),
                              in.wedge_values.end());
      for (const auto& w : in.face_wedges)
        out.face_wedges.push_back(
            {w[0] + copy * wedges, w[1] + copy * wedges, w[2] + copy * wedges});
    }
  out.positions_are_float = all_positions_are_float(out.positions);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "parapm-tile: writes N x M copies of a mesh side by side (along x, then y) as one mesh, "
      "for scaling benchmarks.\nExit status: 0 success, 2 an error (one line on stderr)."};
  std::string in_path, out_path, grid_text = "2x2";
  double gap = 0.05;
  app.add_option("input", in_path, "Mesh to copy (OBJ, PLY, OFF, STL, optionally .gz)")
      ->required()
      ->check(CLI::ExistingFile);
  app.add_option("output", out_path, "Mesh to write (its extension picks the format)")->required();
  app.add_option("--grid", grid_text, "Copies along x, then rows along y: NxM")
      ->capture_default_str();
  app.add_option("--gap", gap, "Space between copies, as a fraction of the mesh's extent")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 10.0));
  try {
    app.parse(argc, argv);
    const parapm::Mesh in = parapm::read_mesh(in_path);
    const parapm::Mesh out = tiled(in, parse_grid(grid_text), gap);
    parapm::write_mesh(out, out_path);
    std::printf("%s: %zu vertices, %zu faces\n", out_path.c_str(), out.vertex_count(),
                out.face_count());
    return 0;
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "parapm-tile: %s\n", e.what());
    return 2;
  }
}
