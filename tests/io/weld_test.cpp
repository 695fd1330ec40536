// Every reader welds exactly coincident vertices (engine/io/weld.cpp): a surface stored as
// separate pieces (a triangle soup, parts meeting at duplicated vertices) reads as one, its
// attributes kept per corner.
#include <gtest/gtest.h>

#include <string>

#include "io/mesh_io.h"

namespace parapm {
namespace {

// Two triangles of a square, each with its own three vertices; the shared corners are at the
// same places (one of them as -0).
TEST(Weld, ASoupOfTwoTrianglesReadsAsOneSurfaceInEveryFormat) {
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n";
  const std::string off =
      "OFF\n6 2 0\n0 0 0\n1 0 0\n1 1 0\n-0 0 0\n1 1 0\n0 1 0\n"
      "3 0 1 2\n3 3 4 5\n";
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n-0 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 3 4 5\n";
  for (const auto& [name, bytes] :
       {std::pair{"soup.obj", obj}, std::pair{"soup.off", off}, std::pair{"soup.ply", ply}}) {
    ReadReport report;
    const Mesh mesh = read_mesh_from_memory(bytes, name, &report);
    EXPECT_EQ(report.welded_vertices, 2u) << name;
    EXPECT_EQ(mesh.vertex_count(), 6u) << name << ": the merged vertices stay, unused";
    EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 5}})) << name;
  }
}

// Attributes that differ across the weld stay per corner: the two pieces' corners at one
// place become two wedges of one vertex.
TEST(Weld, AttributesStayPerCorner) {
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
      "property float z\nproperty float s\nproperty float t\nelement face 2\n"
      "property list uchar int vertex_indices\nend_header\n"
      "0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 0 0 0.5 0\n1 1 0 0.5 1\n0 1 0 0 1\n3 0 1 2\n3 3 4 5\n";
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory(ply, "uv.ply", &report);
  EXPECT_EQ(report.welded_vertices, 2u);
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}, {0, 2, 5}}));
  ASSERT_EQ(mesh.face_wedges.size(), 2u);
  const WedgeId second_first_corner = mesh.face_wedges[1][0];
  EXPECT_EQ(mesh.wedge_vertex[second_first_corner], 0u);
  EXPECT_EQ(mesh.wedge(second_first_corner)[mesh.layout.texcoord_offset()], 0.5f);
  EXPECT_EQ(mesh.wedge(mesh.face_wedges[0][0])[mesh.layout.texcoord_offset()], 0.0f);
}

TEST(Weld, NothingCoincidentChangesNothing) {
  ReadReport report;
  const Mesh mesh = read_mesh_from_memory("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t.obj", &report);
  EXPECT_EQ(report.welded_vertices, 0u);
  EXPECT_EQ(mesh.faces, (std::vector<Triangle>{{0, 1, 2}}));
}

}  // namespace
}  // namespace parapm
