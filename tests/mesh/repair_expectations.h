// What every repair must satisfy, whatever the input: the output is an oriented manifold with
// consistent wedges, and merging the copies back (input_vertex, input_wedge) gives back the
// input's faces, positions and attributes, minus exactly the removed faces.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "mesh/mesh_checks.h"
#include "mesh/repair.h"

namespace parapm::testing {

// How the output is numbered: as the input (rules 1-4; RepairOptions::spatial_order off), or
// in any order (rule 5 on: the maps back to the input are checked, not the order).
enum class RepairOrder { kInput, kAny };

inline void expect_faithful_repair(const Mesh& input, const RepairedMesh& repaired,
                                   RepairOrder order = RepairOrder::kInput) {
  const Mesh& mesh = repaired.mesh;
  const RepairReport& report = repaired.report;
  std::string why;
  EXPECT_TRUE(is_oriented_manifold(mesh, &why)) << why;
  EXPECT_TRUE(wedges_are_consistent(mesh, &why)) << why;
  EXPECT_EQ(mesh.layout, input.layout);
  EXPECT_EQ(mesh.positions_are_float, input.positions_are_float);

  // Faces: the input's (in their order unless renumbered), minus the removed ones, up to
  // merging copies; each input face at most once.
  ASSERT_EQ(repaired.input_face.size(), mesh.face_count());
  EXPECT_EQ(mesh.face_count() + report.degenerate_faces_removed + report.duplicate_faces_removed,
            input.face_count());
  ASSERT_EQ(repaired.input_vertex.size(), mesh.vertex_count());
  std::vector<uint8_t> face_used(input.face_count(), 0);
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    const FaceId from = repaired.input_face[f];
    ASSERT_LT(from, input.face_count());
    ASSERT_FALSE(face_used[from]) << "input face " << from << " twice";
    face_used[from] = 1;
    if (f && order == RepairOrder::kInput) {
      ASSERT_LT(repaired.input_face[f - 1], from) << "face " << f;
    }
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(repaired.input_vertex[mesh.faces[f][i]], input.faces[from][i])
          << "face " << f << " corner " << i;
    }
  }

  // Vertices: each kept input vertex once, plus its copies; in input order, the originals keep
  // their order and come first, copies follow.
  const size_t originals = mesh.vertex_count() - report.vertex_copies_added;
  EXPECT_EQ(originals + report.unreferenced_vertices_removed, input.vertex_count());
  std::vector<uint8_t> vertex_used(input.vertex_count(), 0);
  size_t distinct = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const VertexId from = repaired.input_vertex[v];
    ASSERT_LT(from, input.vertex_count());
    if (!vertex_used[from]) ++distinct;
    vertex_used[from] = 1;
    if (v && v < originals && order == RepairOrder::kInput) {
      ASSERT_LT(repaired.input_vertex[v - 1], from);
    }
    ASSERT_EQ(mesh.positions[v], input.positions[from]) << "vertex " << v;
  }
  EXPECT_EQ(distinct, originals);

  // Wedges: same values, of the same input vertex, used by the same corners.
  if (!input.layout.any()) {
    EXPECT_TRUE(repaired.input_wedge.empty());
    return;
  }
  ASSERT_EQ(repaired.input_wedge.size(), mesh.wedge_count());
  const size_t floats = size_t(input.layout.floats_per_wedge());
  for (size_t w = 0; w < mesh.wedge_count(); ++w) {
    const WedgeId from = repaired.input_wedge[w];
    ASSERT_LT(from, input.wedge_count());
    ASSERT_EQ(repaired.input_vertex[mesh.wedge_vertex[w]], input.wedge_vertex[from]);
    ASSERT_EQ(std::memcmp(mesh.wedge(WedgeId(w)), input.wedge(from), floats * sizeof(float)), 0)
        << "wedge " << w;
  }
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(repaired.input_wedge[mesh.face_wedges[f][i]],
                input.face_wedges[repaired.input_face[f]][i])
          << "face " << f << " corner " << i;
    }
  }
}

// Two repairs gave the same mesh and the same maps back to the input.
inline void expect_same_repair(const RepairedMesh& a, const RepairedMesh& b) {
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.faces, b.mesh.faces);
  EXPECT_EQ(a.mesh.wedge_vertex, b.mesh.wedge_vertex);
  EXPECT_EQ(a.mesh.wedge_values, b.mesh.wedge_values);
  EXPECT_EQ(a.mesh.face_wedges, b.mesh.face_wedges);
  EXPECT_EQ(a.input_vertex, b.input_vertex);
  EXPECT_EQ(a.input_face, b.input_face);
  EXPECT_EQ(a.input_wedge, b.input_wedge);
  EXPECT_EQ(a.report.degenerate_faces_removed, b.report.degenerate_faces_removed);
  EXPECT_EQ(a.report.duplicate_faces_removed, b.report.duplicate_faces_removed);
  EXPECT_EQ(a.report.unreferenced_vertices_removed, b.report.unreferenced_vertices_removed);
  EXPECT_EQ(a.report.nonmanifold_edges, b.report.nonmanifold_edges);
  EXPECT_EQ(a.report.nonmanifold_vertices, b.report.nonmanifold_vertices);
  EXPECT_EQ(a.report.vertex_copies_added, b.report.vertex_copies_added);
  EXPECT_EQ(a.report.zero_area_faces, b.report.zero_area_faces);
}

}  // namespace parapm::testing
