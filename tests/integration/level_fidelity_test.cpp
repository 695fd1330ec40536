// Levels that look like their input on the kinds of mesh where they once did not: a large
// open square carrying many small parts, a closed textured surface with UV seams everywhere,
// and every mesh of ../shared/meshes against the quadric's own levels. Each level is judged
// by its surface distance to the input (engine/measure, both directions, relative to the
// bounding-box diagonal) and by its shape (corners kept).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "drawn_meshes.h"
#include "io/mesh_io.h"
#include "measure/surface_distance.h"
#include "mesh/repair.h"
#include "mesh/repaired_input.h"
#include "pm/levels.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm {
namespace {

constexpr uint64_t kSamples = 20000;

// The whole PM of `metric`, down to `ratio` of the faces or as far as the rules allow.
ProgressiveMesh build(const RepairedMesh& repaired, const std::string& metric, double ratio) {
  SimplifyOptions options;
  options.metric = metric;
  options.target_ratio = ratio;
  return build_progressive_mesh(repaired, options);
}

Mesh level_with_faces(const ProgressiveMesh& pm, size_t faces) {
  return level_of_detail(pm, level_for_faces(pm, faces));
}

bool has_vertex_at(const Mesh& mesh, const Vec3& p) {
  return std::find(mesh.positions.begin(), mesh.positions.end(), p) != mesh.positions.end();
}

// A ground square of two triangles carrying 300 boxes: its collapses are the dearest of the
// scene (each moves its corners by tens of units, a box's by one), so every level above the
// boxes' legal minimum (4 faces each: 1202 in all) keeps the square. The energy once keyed
// every collapse that merges two crease corners (all of a box's) after every other collapse,
// however dear: its 50% level was the square cut to a triangle (Hausdorff 0.13).
TEST(LevelFidelity, GroundSquareKeepsItsCornersAmongSmallBoxes) {
  const Mesh scene = testing::ground_with_boxes(300);
  const RepairedMesh repaired = repair_mesh(scene);
  const Mesh input = repaired_input(repaired);
  for (const char* metric : {"quadric", "energy"}) {
    const ProgressiveMesh pm = build(repaired, metric, 0.02);
    for (size_t faces : {scene.faces.size() / 2, size_t(1300)}) {
      const Mesh level = level_with_faces(pm, faces);
      const SurfaceDistance d = surface_distance(input, level, kSamples);
      std::printf("ground and boxes %-8s %zu faces: rms %.3g hausdorff %.3g\n", metric,
                  level.face_count(), d.rms, d.hausdorff);
      for (const Vec3& corner :
           {Vec3{0, 0, 0}, Vec3{100, 0, 0}, Vec3{100, 100, 0}, Vec3{0, 100, 0}})
        EXPECT_TRUE(has_vertex_at(level, corner))
            << metric << " at " << level.face_count() << " faces lost the corner " << corner[0]
            << ", " << corner[1];
      EXPECT_LT(d.hausdorff, 0.01) << metric << " at " << level.face_count() << " faces";
    }
  }
}

// A double-sided disc (each face and its reverse: a thin part as exporters write it) keeps its
// round rim as the one-sided disc keeps its boundary. Along the rim the two sides' faces lie
// back to back, their planes one: a quadric of face planes alone is blind to the rim moving
// inwards, and once cut the double-sided disc's rim to a polygon (openfoam-motorbike-332k's
// discs) at no cost: 0.19-0.25 of the disc's size off. Within 2.5x of the one-sided disc's
// distance: at 55 faces a side the energy's one-sided disc is 2.9e-4 off, its double-sided
// one 5.9e-4 (the quadric's 5.4e-4 and 3.7e-4).
TEST(LevelFidelity, ADoubleSidedDiscKeepsItsRimAsTheOneSidedDiscDoes) {
  const Mesh one_side = testing::disc(12, 96);
  const RepairedMesh one = repair_mesh(one_side);
  const RepairedMesh two = repair_mesh(testing::double_sided(one_side));
  const Mesh one_input = repaired_input(one), two_input = repaired_input(two);
  for (const char* metric : {"quadric", "energy"}) {
    const ProgressiveMesh one_pm = build(one, metric, 0.02);
    const ProgressiveMesh two_pm = build(two, metric, 0.02);
    for (size_t faces : {one_side.faces.size() / 10, one_side.faces.size() / 40}) {
      const SurfaceDistance d1 =
          surface_distance(one_input, level_with_faces(one_pm, faces), kSamples);
      const SurfaceDistance d2 =
          surface_distance(two_input, level_with_faces(two_pm, 2 * faces), kSamples);
      std::printf("disc %-8s %zu faces a side: hausdorff one-sided %.3g, double-sided %.3g\n",
                  metric, faces, d1.hausdorff, d2.hausdorff);
      EXPECT_LE(d2.hausdorff, 2.5 * d1.hausdorff + 1e-9) << metric << " at " << faces << " faces";
    }
  }
}

// The textured bunny (UV seams everywhere: most collapses late in the build change a seam's
// topology): the energy's levels at 10% and 2% within 1.5x the quadric's RMS. Keyed after
// every ordinary collapse, such collapses waited while the seams were simplified along
// themselves whatever that cost: 2.4x and 3.5x the quadric's RMS.
TEST(LevelFidelity, TexturedSurfaceWithSeamsEverywhereFollowsItsShape) {
  const RepairedMesh repaired =
      repair_mesh(read_mesh(testing::test_data("pymeshlab-bunny-textured-10k.obj")));
  const Mesh input = repaired_input(repaired);
  const ProgressiveMesh quadric = build(repaired, "quadric", 0.02);
  const ProgressiveMesh energy = build(repaired, "energy", 0.02);
  const size_t faces = repaired.mesh.face_count();
  for (size_t target : {faces / 10, faces / 50}) {
    const SurfaceDistance q = surface_distance(input, level_with_faces(quadric, target), kSamples);
    const SurfaceDistance e = surface_distance(input, level_with_faces(energy, target), kSamples);
    std::printf("textured bunny at %zu faces: rms quadric %.3g energy %.3g (%.2fx)\n", target,
                q.rms, e.rms, e.rms / q.rms);
    EXPECT_LE(e.rms, 1.5 * q.rms) << target << " faces";
  }
}

// Every mesh of ../shared/meshes, both metrics, at 50%, 10% and 2% of its faces: neither
// metric's level is much farther from the input (Hausdorff) than the other's at the same face
// count, unless both are within kNegligible of the diagonal. A guard without a peer: a level
// that has turned into another shape (a square cut to a triangle, a sheet for a solid, a
// vertex slid past a feature's end) is far from the input under one metric while the other
// keeps the shape. The energy's levels within kMetricGap of the quadric's; the quadric's
// within kQuadricGap of the energy's, which measures its distances to the input itself and is
// the closer of the two in Hausdorff on scans (horse-97k at 50%: the quadric 5.6x, as far as
// CGAL Lindstrom-Turk's level).
constexpr double kMetricGap = 3;
constexpr double kQuadricGap = 10;
constexpr double kNegligible = 1e-4;

// The energy's known gaps, still open (issue 33), guarded at today's figures (2026-11-27), not
// excused: on chair-dupfaces-13k, double-sided all over, its 50% and 10% levels are 5.8x and
// 2.8x the quadric's (0.0015 and 0.021 of the diagonal), where a face laid over a gap between
// two parts is what E_dist (the input's points against the level) does not see; whether a
// face lands there changes with the extra points' seed (DECISIONS.md, "rims of double-sided
// sheets"); openfoam-motorbike-332k's 50% level is 3.5x the quadric's (2.0e-4 of the
// diagonal; metro puts it at 0.10x CGAL Lindstrom-Turk's Hausdorff: bench/fidelity.sh).
// lion-17k's 2% level (an open hole the level must not close in over) and cad-counter-84k's
// 10% level (a round rim) are held at kMetricGap (DECISIONS.md, "boundary planes" and "No
// crease curves by default").
double energy_gap(const std::string& mesh) {
  if (mesh == "openfoam-motorbike-332k.obj.gz") return 4;
  if (mesh == "chair-dupfaces-13k.obj") return 7;
  return kMetricGap;
}

class SharedMeshLevels : public ::testing::TestWithParam<std::string> {};

TEST_P(SharedMeshLevels, NeitherMetricIsFarBehindTheOther) {
  const std::filesystem::path path = testing::shared_meshes_dir() / GetParam();
  const RepairedMesh repaired = repair_mesh(read_mesh(path.string()));
  const Mesh input = repaired_input(repaired);
  const ProgressiveMesh quadric = build(repaired, "quadric", 0.02);
  const ProgressiveMesh energy = build(repaired, "energy", 0.02);
  const size_t faces = repaired.mesh.face_count();
  for (size_t target : {faces / 2, faces / 10, faces / 50}) {
    const Mesh q_level = level_with_faces(quadric, target);
    const Mesh e_level = level_with_faces(energy, target);
    // At the larger of the two levels' face counts (one may stop above the target).
    const size_t common = std::max(q_level.face_count(), e_level.face_count());
    const SurfaceDistance q = surface_distance(input, level_with_faces(quadric, common), kSamples);
    const SurfaceDistance e = surface_distance(input, level_with_faces(energy, common), kSamples);
    std::printf("%-36s %7zu faces: hausdorff quadric %.3g energy %.3g; rms %.3g %.3g\n",
                GetParam().c_str(), common, q.hausdorff, e.hausdorff, q.rms, e.rms);
    EXPECT_LE(e.hausdorff, std::max(energy_gap(GetParam()) * q.hausdorff, kNegligible))
        << "energy at " << common << " faces";
    EXPECT_LE(q.hausdorff, std::max(kQuadricGap * e.hausdorff, kNegligible))
        << "quadric at " << common << " faces";
  }
}

std::vector<std::string> shared_mesh_names() {
  std::vector<std::string> names;
  for (const auto& path : testing::shared_meshes()) names.push_back(path.filename().string());
  return names;
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Every, SharedMeshLevels, ::testing::ValuesIn(shared_mesh_names()),
                         test_name);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(SharedMeshLevels);

}  // namespace
}  // namespace parapm
