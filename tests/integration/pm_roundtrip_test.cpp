// The whole local pipeline on real meshes: read, repair, simplify with each metric (quadric,
// energy) down as far as collapses stay legal, write the .pm, read it back, and check that
// applying every vertex split gives back the input exactly. Runs on the committed meshes, and
// on every mesh of ../shared/meshes under 500k faces when that folder is present.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <sstream>

#include "io/mesh_io.h"
#include "mesh/repaired_input.h"
#include "pm/levels.h"
#include "pm/mesh_compare.h"
#include "pm/pm_file.h"
#include "pm/pm_restore.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm {
namespace {

struct RoundTrip {
  std::string bytes;
  ProgressiveMesh pm;
  Mesh expected;
};

RoundTrip build_and_reload(const std::string& path, const SimplifyOptions& options) {
  RepairOptions repair_options;
  repair_options.keep_unreferenced = options.keep_order;
  const RepairedMesh repaired = repair_mesh(read_mesh(path), repair_options);
  RoundTrip result;
  const ProgressiveMesh built = build_progressive_mesh(repaired, options);
  std::ostringstream out;
  write_pm(built, out);
  result.bytes = out.str();
  std::istringstream in(result.bytes);
  result.pm = read_pm(in, path);
  result.expected = repaired_input(repaired);
  return result;
}

void expect_lossless(const std::string& path, const SimplifyOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const RoundTrip rt = build_and_reload(path, options);
  const Mesh restored = restore_input(rt.pm);
  const MeshDifference diff =
      compare_meshes_exact(restored, rt.expected, /*same_numbering=*/options.keep_order);
  EXPECT_TRUE(diff.equal) << path << ": " << diff.first_difference;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "lossless %-8s %-45s %8zu faces -> base %6zu faces, %7zu vsplits, %7zu bytes, %.2f s\n",
      options.metric.c_str(), std::filesystem::path(path).filename().c_str(),
      rt.expected.face_count(), rt.pm.base.face_count(), rt.pm.splits.size(), rt.bytes.size(),
      seconds);
}

const char* kCommitted[] = {"pymeshlab-bunny-textured-10k.obj",
                            "pymeshlab-colored-airplane-11k.ply",
                            "cad-featuretype-3k.stl",
                            "stratocaster-9k.ply",
                            "cad-cycloidal-43k.ply",
                            "gmsh-aneurysm-20k.stl.gz"};

TEST(PmRoundTrip, CommittedMeshesAreLossless) {
  for (const char* name : kCommitted) expect_lossless(testing::test_data(name), {});
}

SimplifyOptions energy_options(double samples_per_face = 0) {
  SimplifyOptions options;
  options.metric = "energy";
  options.samples_per_face = samples_per_face;
  return options;
}

TEST(PmRoundTrip, CommittedMeshesAreLosslessWithTheEnergyMetric) {
  for (const char* name : kCommitted) expect_lossless(testing::test_data(name), energy_options());
  expect_lossless(testing::test_data("pymeshlab-colored-airplane-11k.ply"), energy_options(2));
}

TEST(PmRoundTrip, EnergySameSeedSameBytesOtherSeedOtherPoints) {
  const std::string path = testing::test_data("stratocaster-9k.ply");
  SimplifyOptions options = energy_options(1);
  options.target_ratio = 0.1;
  const std::string first = build_and_reload(path, options).bytes;
  EXPECT_EQ(first, build_and_reload(path, options).bytes);
  options.seed = 2;
  EXPECT_NE(first, build_and_reload(path, options).bytes) << "the extra points are drawn anew";
}

TEST(PmRoundTrip, KeepOrderGivesBackTheInputNumbering) {
  SimplifyOptions options;
  options.keep_order = true;
  for (const char* name : kCommitted) expect_lossless(testing::test_data(name), options);
}

TEST(PmRoundTrip, SameInputSameBytes) {
  SimplifyOptions options;
  options.target_ratio = 0.05;
  const std::string path = testing::test_data("pymeshlab-colored-airplane-11k.ply");
  EXPECT_EQ(build_and_reload(path, options).bytes, build_and_reload(path, options).bytes);
}

TEST(PmRoundTrip, TargetFaceCountIsReached) {
  const std::string path = testing::test_data("pymeshlab-bunny-textured-10k.obj");
  for (double ratio : {0.5, 0.1, 0.02}) {
    SimplifyOptions options;
    options.target_ratio = ratio;
    const RoundTrip rt = build_and_reload(path, options);
    const size_t target = target_face_count(rt.expected.face_count(), options);
    EXPECT_LE(rt.pm.base.face_count(), target) << "ratio " << ratio;
    EXPECT_GE(rt.pm.base.face_count() + 2, target) << "ratio " << ratio;
  }
}

TEST(PmRoundTrip, LevelsHoldAtMostTheAskedFaces) {
  const RoundTrip rt = build_and_reload(testing::test_data("stratocaster-9k.ply"), {});
  const size_t full = rt.pm.full_face_count();
  const size_t base = rt.pm.base.face_count();
  EXPECT_EQ(level_for_faces(rt.pm, base / 2), 0u) << "below the base mesh: the base mesh";
  for (size_t faces : {full, full / 2, full / 10, base + (full - base) / 50, base}) {
    const size_t level = level_for_faces(rt.pm, faces);
    const Mesh lod = level_of_detail(rt.pm, level);
    EXPECT_LE(lod.face_count(), faces);
    if (level < rt.pm.splits.size()) {  // one more split would exceed the budget
      EXPECT_GT(level_of_detail(rt.pm, level + 1).face_count(), faces);
    }
  }
}

TEST(PmRoundTrip, ErrorBoundsDoNotIncreaseWithRefinement) {
  const RoundTrip rt = build_and_reload(testing::test_data("gmsh-aneurysm-20k.stl.gz"), {});
  for (size_t i = 1; i < rt.pm.splits.size(); ++i)
    ASSERT_LE(rt.pm.splits[i].error, rt.pm.splits[i - 1].error) << "split " << i;
  const double bound = rt.pm.splits[rt.pm.splits.size() / 2].error;
  const size_t level = level_for_error(rt.pm, bound);
  EXPECT_LE(level, rt.pm.splits.size() / 2);
}

TEST(PmRoundTrip, EverySharedMeshUnder500kFacesIsLossless) {
  const auto meshes = testing::shared_meshes();
  if (meshes.empty()) GTEST_SKIP() << "../shared/meshes is not present";
  for (const auto& path : meshes) {
    ReadReport report;
    Mesh mesh;
    try {
      mesh = read_mesh(path.string(), &report);
    } catch (const Error& e) {
      std::printf("rejected %s: %s\n", path.filename().c_str(), e.what());
      continue;
    }
    if (mesh.face_count() >= 500000) {
      std::printf("skipped  %s (%zu faces)\n", path.filename().c_str(), mesh.face_count());
      continue;
    }
    expect_lossless(path.string(), {});
  }
}

// The energy metric on every shared mesh under 500k faces: the whole PM below 100k faces; a
// PM down to 5% above, to keep the suite's time in bounds (the round trip is the same code
// whatever the base mesh).
TEST(PmRoundTrip, EverySharedMeshUnder500kFacesIsLosslessWithTheEnergyMetric) {
  const auto meshes = testing::shared_meshes();
  if (meshes.empty()) GTEST_SKIP() << "../shared/meshes is not present";
  for (const auto& path : meshes) {
    Mesh mesh;
    try {
      mesh = read_mesh(path.string());
    } catch (const Error& e) {
      continue;  // reported by the quadric test above
    }
    if (mesh.face_count() >= 500000) continue;
    SimplifyOptions options = energy_options();
    if (mesh.face_count() >= 100000) options.target_ratio = 0.05;
    expect_lossless(path.string(), options);
  }
}

}  // namespace
}  // namespace parapm
