// Reads every file of ../shared/meshes and checks its triangle and vertex counts against
// INVENTORY.tsv (faces: triangles after fan-splitting polygons, strips without their
// degenerate joints; vertices: as stored, STL after welding equal coordinates). Prints one line
// per file. Does nothing when the folder is absent.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/formats.h"
#include "io/mesh_io.h"
#include "io_test_util.h"
#include "test_support.h"

namespace parapm {
namespace {

struct InventoryRow {
  uint64_t faces = 0;
  uint64_t vertices = 0;
  std::string format;
};

std::map<std::string, InventoryRow> read_inventory(const std::filesystem::path& file) {
  std::map<std::string, InventoryRow> rows;
  std::ifstream in(file);
  std::string line;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, '\t');) cells.push_back(cell);
    if (header.empty()) {
      header = cells;
      continue;
    }
    std::map<std::string, std::string> row;
    for (size_t i = 0; i < cells.size() && i < header.size(); ++i) row[header[i]] = cells[i];
    InventoryRow r;
    r.faces = std::stoull(row.at("faces"));
    r.vertices = std::stoull(row.at("vertices"));
    r.format = row["format"];
    rows[row.at("file")] = r;
  }
  return rows;
}

TEST(SharedMeshes, EveryFileLoadsWithTheInventoryCounts) {
  const auto files = testing::shared_meshes();
  if (files.empty()) GTEST_SKIP() << "no shared meshes folder at " << testing::shared_meshes_dir();
  const auto inventory = read_inventory(testing::shared_meshes_dir() / "INVENTORY.tsv");
  ASSERT_FALSE(inventory.empty()) << "INVENTORY.tsv is missing or empty";

  std::printf("%-36s %-24s %9s %9s %8s\n", "file", "format", "faces", "vertices", "seconds");
  for (const auto& path : files) {
    const std::string name = path.filename().string();
    SCOPED_TRACE(name);
    ReadReport report;
    Mesh mesh;
    const auto start = std::chrono::steady_clock::now();
    try {
      mesh = read_mesh(path.string(), &report);
    } catch (const std::exception& e) {
      std::printf("%-36s FAILED: %s\n", name.c_str(), e.what());
      ADD_FAILURE() << e.what();
      continue;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::string format = std::string(format_name(report.format)) + "-" + report.encoding +
                               (report.gzip ? "+gz" : "");
    std::printf("%-36s %-24s %9zu %9zu %8.3f\n", name.c_str(), format.c_str(), mesh.face_count(),
                mesh.vertex_count(), seconds);
    std::fflush(stdout);

    const auto row = inventory.find(name);
    if (row == inventory.end()) {
      ADD_FAILURE() << name << " is not listed in INVENTORY.tsv";
      continue;
    }
    EXPECT_EQ(mesh.face_count(), row->second.faces);
    EXPECT_EQ(mesh.vertex_count(), row->second.vertices);
    EXPECT_EQ(report.gzip, row->second.format.find("+gz") != std::string::npos);
  }
}

// Every shared mesh reads the same in chunks, and survives OBJ and binary PLY (in memory): same
// corners, bit for bit.
TEST(SharedMeshes, EveryFileRoundTripsThroughObjAndPly) {
  const auto files = testing::shared_meshes();
  if (files.empty()) GTEST_SKIP() << "no shared meshes folder at " << testing::shared_meshes_dir();
  for (const auto& path : files) {
    const std::string name = path.filename().string();
    SCOPED_TRACE(name);
    ReadReport report;
    const Mesh mesh = read_mesh(path.string(), &report);
    // Read in chunks side by side (the welds, ascii PLY bodies): the same mesh.
    ChunkedLoops loops(16, 2);
    ReadReport chunked_report;
    const Mesh chunked = read_mesh(path.string(), &chunked_report, {}, &loops);
    EXPECT_EQ(chunked.positions, mesh.positions);
    EXPECT_EQ(chunked.faces, mesh.faces);
    EXPECT_EQ(chunked.face_wedges, mesh.face_wedges);
    EXPECT_EQ(chunked.wedge_values, mesh.wedge_values);
    EXPECT_EQ(chunked_report.welded_vertices, report.welded_vertices);
    EXPECT_EQ(chunked_report.polygons, report.polygons);
    const Mesh obj = read_mesh_from_memory(io::write_obj(mesh), name + ".obj");
    testing::expect_same_corners(mesh, obj);
    const Mesh ply = read_mesh_from_memory(io::write_ply(mesh, false), name + ".ply");
    // PLY stores colours as uchar: exact for colours that came from uchar (PLY files).
    testing::expect_same_corners(mesh, ply,
                                 !mesh.layout.colors || report.format == MeshFormat::kPly);
  }
}

}  // namespace
}  // namespace parapm
