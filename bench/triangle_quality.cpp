// parapm-triangle-quality MESH...: the shape of each mesh's triangles (engine/measure/
// triangle_quality.h), one JSON line per mesh, for the benchmark report beside metro's
// distances. The mesh is read as written (no repair: a degenerate face is a sliver too).
// Exit status: 0 success, 2 an error (one line on stderr).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/mesh_io.h"
#include "measure/triangle_quality.h"
#include "util/error.h"

int main(int argc, char** argv) {
  CLI::App app{
      "parapm-triangle-quality: per mesh, the median of its triangles' least angles and the "
      "fractions of triangles whose least angle is below 1, 5 and 10 degrees, as one JSON "
      "line.\nExit status: 0 success, 2 an error (one line on stderr)."};
  std::vector<std::string> meshes;
  app.add_option("meshes", meshes, "Meshes (OBJ, PLY, OFF, STL, optionally gzip-compressed)")
      ->required()
      ->check(CLI::ExistingFile);
  try {
    app.parse(argc, argv);
    for (const std::string& path : meshes) {
      const parapm::TriangleQuality q = parapm::triangle_quality(parapm::read_mesh(path));
      std::cout << nlohmann::json{{"mesh", path},
                                  {"faces", q.faces},
                                  {"min_angle_median_deg", q.min_angle_median},
                                  {"below_1_deg", q.below_1},
                                  {"below_5_deg", q.below_5},
                                  {"below_10_deg", q.below_10}}
                       .dump()
                << std::endl;
    }
    return 0;
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const parapm::Error& e) {
    std::fprintf(stderr, "parapm-triangle-quality: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "parapm-triangle-quality: %s\n", e.what());
    return 2;
  }
}
