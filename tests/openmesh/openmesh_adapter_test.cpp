// The OpenMesh adapters (include/parapm/openmesh.h) on the committed meshes and, when present,
// the shared ones: a mesh taken through an OpenMesh TriMesh and back has the same corners, and
// builds the same PM where its wedges' numbering is the readers' (no attributes, or one set per
// vertex; attributes per corner are numbered in OpenMesh's face order, and the build's ties
// follow the numbering: that PM is checked lossless instead); a
// level taken to OpenMesh, written as .om by OpenMesh's writer and read back with
// read_openmesh is the level, corner by corner; OpenMesh's reader gives what ParaPM's gives on
// the files both read; bad files are clear errors.
#include <gtest/gtest.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include <parapm/engine.h>
#include <parapm/openmesh.h>

#include "test_support.h"

namespace parapm {
namespace {

namespace fs = std::filesystem;
using openmesh::TriMesh;

// A folder of the test's own, removed at its end.
struct TempFolder {
  fs::path path =
      fs::temp_directory_path() / ("parapm_openmesh_test_" + std::to_string(::getpid()));
  TempFolder() { fs::create_directories(path); }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::vector<fs::path> meshes_to_try() {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(PARAPM_TEST_DATA_DIR))
    if (format_from_name(entry.path().string()) != MeshFormat::kUnknown)
      out.push_back(entry.path());
  for (const fs::path& shared : testing::shared_meshes())
    if (fs::file_size(shared) < (8u << 20))
      out.push_back(shared);  // the larger ones add time, not cases
  std::sort(out.begin(), out.end());
  return out;
}

// Each face's corners: position and attribute values (wedge numbering aside).
std::vector<std::vector<double>> corners(const Mesh& mesh) {
  std::vector<std::vector<double>> out;
  const int floats = mesh.layout.floats_per_wedge();
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = mesh.positions[mesh.faces[f][size_t(k)]];
      std::vector<double> corner(p.begin(), p.end());
      if (floats) {
        const float* w = mesh.wedge(mesh.face_wedges[f][size_t(k)]);
        corner.insert(corner.end(), w, w + floats);
      }
      out.push_back(std::move(corner));
    }
  return out;
}

// The faces as a set: each face's three corners rotated to start at the least, sorted (a PM's
// full level has the input's faces in its own order).
std::vector<std::vector<double>> face_set(const Mesh& mesh) {
  const std::vector<std::vector<double>> c = corners(mesh);
  std::vector<std::vector<double>> faces;
  for (size_t f = 0; f < c.size(); f += 3) {
    const size_t first =
        std::min({f, f + 1, f + 2}, [&](size_t a, size_t b) { return c[a] < c[b]; });
    std::vector<double> face;
    for (size_t k = 0; k < 3; ++k) {
      const auto& corner = c[f + (first - f + k) % 3];
      face.insert(face.end(), corner.begin(), corner.end());
    }
    faces.push_back(std::move(face));
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

TEST(OpenMeshAdapter, AMeshThroughOpenMeshBuildsTheSamePm) {
  size_t same_bytes = 0, lossless = 0, not_for_openmesh = 0;
  for (const fs::path& path : meshes_to_try()) {
    SCOPED_TRACE(path.filename().string());
    // The mesh as read, as an OpenMesh mesh would hold it: OpenMesh keeps no non-manifold or
    // degenerate face, so those files are ParaPM's readers' (and repair's) alone.
    const Mesh input = read_mesh(path.string());
    Mesh back;
    try {
      back = openmesh::from_openmesh(openmesh::to_openmesh<TriMesh>(input));
    } catch (const Error&) {
      ++not_for_openmesh;
      continue;
    }
    ASSERT_TRUE(corners(back) == corners(input));
    SimplifyOptions options;
    options.target_ratio = 0.05;
    const RepairedMesh repaired = repair_mesh(input);
    const ProgressiveMesh direct = build_progressive_mesh(repaired, options);
    const ProgressiveMesh through = build_progressive_mesh(repair_mesh(back), options);
    const Mesh& mesh = input;
    bool canonical_wedges = !mesh.layout.any() || mesh.wedge_count() == mesh.vertex_count();
    for (WedgeId w = 0; canonical_wedges && w < mesh.wedge_count(); ++w)
      canonical_wedges = mesh.wedge_vertex[w] == w;
    if (canonical_wedges) {
      EXPECT_TRUE(testing::pm_bytes(through) == testing::pm_bytes(direct)) << "another PM";
      ++same_bytes;
    } else {
      EXPECT_TRUE(face_set(level_of_detail(through, through.splits.size())) == face_set(back))
          << "a PM that does not give its input back";
      ++lossless;
    }
  }
  std::printf(
      "%zu meshes: %zu the same .pm, %zu with attributes per corner lossless, %zu not for "
      "OpenMesh\n",
      same_bytes + lossless + not_for_openmesh, same_bytes, lossless, not_for_openmesh);
  EXPECT_GT(same_bytes, 0u);
}

TEST(OpenMeshAdapter, ALevelWrittenByOpenMeshReadsBackAsTheLevel) {
  const TempFolder dir;
  for (const char* name : {"pymeshlab-bunny-textured-10k.obj", "pymeshlab-colored-airplane-11k.ply",
                           "stratocaster-9k.ply"}) {
    SCOPED_TRACE(name);
    SimplifyOptions options;
    options.target_ratio = 0.05;
    const ProgressiveMesh pm =
        build_progressive_mesh(repair_mesh(read_mesh(testing::test_data(name))), options);
    const Mesh level = level_of_detail(pm, level_for_faces(pm, pm.base.faces.size() * 4));
    const TriMesh om = openmesh::to_openmesh<TriMesh>(level);
    EXPECT_EQ(om.n_faces(), level.faces.size());
    // In memory, every attribute per corner.
    EXPECT_EQ(corners(openmesh::from_openmesh(om)), corners(level));
    // Through OpenMesh's .om writer and read_openmesh: positions and faces; the attributes
    // OpenMesh's .om keeps (per vertex) are each vertex's first corner's.
    const std::string file = (dir.path / "level.om").string();
    OpenMesh::IO::Options write_options;
    ASSERT_TRUE(OpenMesh::IO::write_mesh(om, file, write_options));
    const Mesh read = openmesh::read_openmesh(file);
    ASSERT_EQ(read.positions, level.positions);
    ASSERT_EQ(read.faces, level.faces);
    // The command line takes .om through the same reader.
    const std::string parapm = std::string(PARAPM_BINARY_DIR) + "/parapm --log-level warn ";
    const std::string pm_file = (dir.path / "level.pm").string();
    ASSERT_EQ(
        std::system((parapm + "simplify " + file + " -o " + pm_file + " --ratio 0.5").c_str()), 0);
    ASSERT_EQ(
        std::system((parapm + "check " + pm_file + " --against " + file + " > /dev/null").c_str()),
        0);
  }
}

TEST(OpenMeshAdapter, OpenMeshsReaderGivesWhatParapmsGives) {
  size_t compared = 0;
  for (const fs::path& path : meshes_to_try()) {
    const std::string ext = path.extension().string();
    if (ext != ".off" && ext != ".ply" && ext != ".stl") continue;  // (OpenMesh reads no .gz)
    SCOPED_TRACE(path.filename().string());
    ReadReport report;
    const Mesh ours = read_mesh(path.string(), &report);
    // ParaPM's readers weld coincident vertices of every format, OpenMesh's only STL's.
    if (report.welded_vertices > 0 && report.format != MeshFormat::kStl) continue;
    Mesh theirs;
    try {
      theirs = openmesh::read_openmesh(path.string());
    } catch (const Error&) {
      continue;  // a file OpenMesh cannot read
    }
    // OpenMesh drops or splits what is not manifold: those files are ParaPM's readers' alone.
    if (theirs.faces.size() != ours.faces.size() ||
        theirs.positions.size() != ours.positions.size())
      continue;
    for (size_t v = 0; v < std::min(theirs.positions.size(), ours.positions.size()); ++v)
      for (int k = 0; k < 3; ++k)
        ASSERT_FLOAT_EQ(float(theirs.positions[v][size_t(k)]), float(ours.positions[v][size_t(k)]));
    EXPECT_EQ(theirs.faces, ours.faces);
    ++compared;
  }
  EXPECT_GT(compared, 0u);
}

TEST(OpenMeshAdapter, WhatOpenMeshCannotReadIsAClearError) {
  const TempFolder dir;
  const std::string file = (dir.path / "broken.om").string();
  std::ofstream(file) << "not an OpenMesh file";
  try {
    openmesh::read_openmesh(file);
    FAIL() << "read";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("broken.om"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace parapm
