// E_scalar (scalar_attributes.h) through the energy metric on drawn meshes: a linear colour
// field is reproduced at every level, a colour seam stays a seam, and the PM gives back the
// input's colours exactly; on a real mesh, the lossless round trip with wedge changes.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "mesh/repaired_input.h"
#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm/pm_restore.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm {
namespace {

// A flat n x n grid on [0, 1]^2 with RGBA colours; colour(x, y, right_side) gives a corner's
// colour, where right_side tells which side of the seam x = 0.5 the face lies on (a mesh
// without a seam ignores it). With `seam`, vertices on x = 0.5 get one wedge per side.
Mesh coloured_grid(int n, bool seam, const std::function<float(double, double, bool)>& red) {
  Mesh m;
  m.layout.colors = true;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      m.positions.push_back({double(i) / (n - 1), double(j) / (n - 1), 0});
  // wedge_of[v][side]
  std::vector<std::array<WedgeId, 2>> wedge_of(m.positions.size(), {kNoId, kNoId});
  auto wedge = [&](VertexId v, bool right) {
    const bool on_seam = seam && std::abs(m.positions[v][0] - 0.5) < 1e-9;
    const int side = on_seam && right ? 1 : 0;
    if (wedge_of[v][side] == kNoId) {
      wedge_of[v][side] = WedgeId(m.wedge_vertex.size());
      m.wedge_vertex.push_back(v);
      const float r = red(m.positions[v][0], m.positions[v][1], right);
      m.wedge_values.insert(m.wedge_values.end(), {r, 0.5f, 0.25f, 1.0f});
    }
    return wedge_of[v][side];
  };
  auto id = [&](int i, int j) { return VertexId(j * n + i); };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const bool right = (i + 0.5) / (n - 1) > 0.5;
      const Triangle lower{id(i, j), id(i + 1, j), id(i + 1, j + 1)};
      const Triangle upper{id(i, j), id(i + 1, j + 1), id(i, j + 1)};
      for (const Triangle& t : {lower, upper}) {
        m.faces.push_back(t);
        m.face_wedges.push_back({wedge(t[0], right), wedge(t[1], right), wedge(t[2], right)});
      }
    }
  return m;
}

// The base mesh of a PM built in energy mode down to `ratio`, with E_scalar at `weight`.
Mesh energy_level(const Mesh& input, double ratio, double weight,
                  ProgressiveMesh* pm_out = nullptr) {
  SimplifyOptions options;
  options.metric = "energy";
  options.target_ratio = ratio;
  options.attribute_weight = weight;
  const RepairedMesh repaired = repair_mesh(input);
  ProgressiveMesh pm = build_progressive_mesh(repaired, options);
  Mesh base = pm.base;
  if (pm_out) *pm_out = std::move(pm);
  return base;
}

float corner_red(const Mesh& m, FaceId f, int k) {
  return m.wedge(m.face_wedges[f][k])[m.layout.color_offset()];
}

TEST(ScalarAttributes, ALinearColourFieldIsReproducedAtACoarseLevel) {
  // red = x: any triangulation interpolates it exactly, so the least-squares values are the
  // field at the vertices' new positions. Without E_scalar a vertex keeps one input colour
  // wherever it moves.
  const Mesh grid = coloured_grid(21, false, [](double x, double, bool) { return float(x); });
  double worst_with = 0, worst_without = 0;
  for (double weight : {0.01, 0.0}) {
    const Mesh base = energy_level(grid, 0.1, weight);
    ASSERT_LE(base.face_count(), 80u);
    double worst = 0;
    for (FaceId f = 0; f < base.face_count(); ++f)
      for (int k = 0; k < 3; ++k)
        worst =
            std::max(worst, std::abs(corner_red(base, f, k) - base.positions[base.faces[f][k]][0]));
    (weight > 0 ? worst_with : worst_without) = worst;
  }
  EXPECT_LT(worst_with, 0.01);
  EXPECT_LT(worst_with, worst_without);
}

TEST(ScalarAttributes, AColourSeamStaysASeam) {
  // Left faces black, right faces red, the vertices on x = 0.5 holding both: at 15% every face
  // still has its side's colour at all three corners.
  const Mesh grid = coloured_grid(21, true, [](double x, double, bool right) {
    return float(right ? 0.5 + 0.5 * x : 0.5 * x);
  });
  ProgressiveMesh pm;
  const Mesh base = energy_level(grid, 0.15, 0.01, &pm);
  for (FaceId f = 0; f < base.face_count(); ++f) {
    const Triangle& t = base.faces[f];
    const double centroid_x =
        (base.positions[t[0]][0] + base.positions[t[1]][0] + base.positions[t[2]][0]) / 3;
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(corner_red(base, f, k),
                  0.5 * base.positions[t[k]][0] + (centroid_x > 0.5 ? 0.5 : 0.0), 1e-2)
          << "face " << f << " corner " << k << " at " << base.positions[t[k]][0] << ", "
          << base.positions[t[k]][1] << " of " << base.positions[t[(k + 1) % 3]][0] << ", "
          << base.positions[t[(k + 1) % 3]][1] << " / " << base.positions[t[(k + 2) % 3]][0] << ", "
          << base.positions[t[(k + 2) % 3]][1] << " wedge " << base.face_wedges[f][k];
  }
  // And the full resolution has the input's colours, bit for bit.
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repair_mesh(grid)), false);
  EXPECT_TRUE(diff.equal) << diff.first_difference;
}

TEST(ScalarAttributes, EveryLevelOfARealMeshHasColoursInRangeAndTheFullLevelIsExact) {
  // The committed colour mesh: E_scalar's values stay colours at every level (clamped to
  // [0, 1]), and the split sequence restores the input (read_pm's validation also checks
  // every wedge change's coarse value against the level it applies to).
  const Mesh input = read_mesh(testing::test_data("pymeshlab-colored-airplane-11k.ply"));
  ProgressiveMesh pm;
  energy_level(input, 0.02, 0.01, &pm);
  EXPECT_FALSE(pm.wedge_changes.empty());
  for (size_t faces : {pm.base.face_count(), size_t(1000), size_t(5000)}) {
    const Mesh level = level_of_detail(pm, level_for_faces(pm, faces));
    for (float value : level.wedge_values) {
      ASSERT_GE(value, 0.0f);
      ASSERT_LE(value, 1.0f);
    }
  }
}

}  // namespace
}  // namespace parapm
