// Quality of the parallel PM against the sequential PM of the same metric: at 50%, 10% and 2%
// of the input faces and at the sequential base's size, the surface distance of the parallel
// level to the input (RMS and Hausdorff, both directions, engine/measure) over the sequential
// level's. Real meshes, all also in ../shared/meshes: a CAD part, a scanned vessel, the
// textured bunny; p = 2, 4, 8, 16 with quadrics, p = 2, 4 with the energy; and a drawn
// double-sided sheet beside a sphere, p = 2, 4, 8, both metrics. Every figure is printed.
//
// What is asserted, per mesh and metric, as regression guards with a margin over the figures
// measured now: the median RMS ratio over the (p, level) cells within 10% (measured: 1.00-1.03),
// the median of the 10% cells alone (the level the rounds hand over at) within 10% (0.98-1.02;
// the CAD part 15%, below),
// the worst cell under RMS 1.35 (1.12; the CAD part 1.5 and the energy's pooled cells 1.6, below)
// and Hausdorff 2.6 (1.87). Issue 5's target, every cell within 5% (RMS) and 10% (Hausdorff),
// is not met on these small meshes (at p = 16 the bunny's subsets hold 600 faces); it is on the
// 203k dragon (bench/parallel_quality.sh). The guards' history: docs/DECISIONS.md, "Test
// guards". One more test, on fandisk from ../shared/meshes, checks the jobs' shares by cheap
// edges against equal shares at the 50% level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "drawn_meshes.h"
#include "measure/surface_distance.h"
#include "mesh/repaired_input.h"
#include "parallel/parallel_build.h"
#include "parallel_test_support.h"
#include "pm/levels.h"
#include "simplify/simplify.h"

namespace parapm::testing {
namespace {

constexpr uint64_t kSamples = 20000;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Ratios {
  std::vector<double> rms;
  std::vector<double> handover_rms;  // the 10% cells: where the rounds hand over by default
  double worst_rms = 0, worst_hausdorff = 0;
  void add(const Ratios& r) {
    rms.insert(rms.end(), r.rms.begin(), r.rms.end());
    handover_rms.insert(handover_rms.end(), r.handover_rms.begin(), r.handover_rms.end());
    worst_rms = std::max(worst_rms, r.worst_rms);
    worst_hausdorff = std::max(worst_hausdorff, r.worst_hausdorff);
  }
};

void expect_near_sequential(const Ratios& r, const std::string& name, double worst_rms = 1.35,
                            double handover_rms = 1.10, double worst_hausdorff = 2.6) {
  EXPECT_LE(median(r.rms), 1.10) << name;
  EXPECT_LE(median(r.handover_rms), handover_rms) << name << ": the rounds' last level is uneven";
  EXPECT_LE(r.worst_rms, worst_rms) << name;
  EXPECT_LE(r.worst_hausdorff, worst_hausdorff) << name;
}

// Per level, parallel over sequential; prints every figure.
Ratios compare(const std::string& name, const RepairedMesh& repaired,
               const SimplifyOptions& options, const std::vector<uint32_t>& ps) {
  const Mesh input = repaired_input(repaired);
  const ProgressiveMesh sequential = build_progressive_mesh(repaired, options);
  const uint64_t faces = repaired.mesh.face_count();
  const std::vector<std::pair<const char*, uint64_t>> levels = {
      {"50%", faces / 2},
      {"10%", faces / 10},
      {"2%", faces / 50},
      {"base", sequential.base.face_count()}};
  std::vector<SurfaceDistance> seq;
  for (const auto& [label, count] : levels)
    seq.push_back(surface_distance(
        input, level_of_detail(sequential, level_for_faces(sequential, count)), kSamples));
  Ratios worst;
  for (uint32_t p : ps) {
    ParallelOptions parallel;
    parallel.subsets = p;
    // p subsets in every round, the hardest case (by default these 10-43k-face meshes would
    // get fewer at p >= 8: ParallelOptions::min_subset_faces).
    parallel.min_subset_faces = 0;
    const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, parallel);
    std::printf("%-28s %-7s p=%-2u", name.c_str(), options.metric.c_str(), p);
    for (size_t i = 0; i < levels.size(); ++i) {
      const Mesh level = level_of_detail(pm, level_for_faces(pm, levels[i].second));
      const SurfaceDistance d = surface_distance(input, level, kSamples);
      const double rms = d.rms / seq[i].rms, hausdorff = d.hausdorff / seq[i].hausdorff;
      std::printf("  %s rms %.3f haus %.3f", levels[i].first, rms, hausdorff);
      worst.rms.push_back(rms);
      if (i == 1) worst.handover_rms.push_back(rms);
      worst.worst_rms = std::max(worst.worst_rms, rms);
      worst.worst_hausdorff = std::max(worst.worst_hausdorff, hausdorff);
    }
    std::printf("\n");
  }
  return worst;
}

// The CAD part's worst cell is guarded at 1.5: its 2% level is below its legal minimum (about
// 2.1k faces: copies of non-manifold vertices whose seam collapses are vetoed), so it is the
// base, whose last hundred collapses, the dearest legal ones, double its error; which of them
// remain moves with the rounds (measured: 0.70-1.09 at p = 2-16). Its 10% cells (the rounds'
// last level), at 1.15: the seam collapses that make its sequential 10% level a third closer to
// the input than locked copies did, the rounds make only where a group's copies and their rings
// lie free inside one job (measured: 1.00-1.19, median 1.07). Its worst Hausdorff cell, at
// 3.0: its 50% level at p = 8, one point 0.0037 from the input against the sequential level's
// 0.0013 (2.87x), a fifth of its 10% level's distance (measured with the quadric placing with
// its star's planes; 0.67-0.74 at the other p).
TEST(ParallelQuality, QuadricLevelsMatchTheSequentialOnes) {
  for (const char* name :
       {"cad-cycloidal-43k.ply", "gmsh-aneurysm-20k.stl.gz", "pymeshlab-bunny-textured-10k.obj"}) {
    SimplifyOptions options;
    options.target_ratio = 0.01;
    const bool cad = name == std::string("cad-cycloidal-43k.ply");
    expect_near_sequential(compare(name, repaired_test_mesh(name), options, {2, 4, 8, 16}), name,
                           cad ? 1.5 : 1.35, cad ? 1.15 : 1.10, cad ? 3.0 : 2.6);
  }
}

// Pooled over three draws of extra points: on a 10k-face mesh one draw moves single cells by
// +-25%, so one run's median says more about the draw than about the build.
TEST(ParallelQuality, EnergyLevelsMatchTheSequentialOnes) {
  for (const char* name : {"gmsh-aneurysm-20k.stl.gz", "pymeshlab-bunny-textured-10k.obj"}) {
    const RepairedMesh repaired = repaired_test_mesh(name);
    Ratios pooled;
    for (const uint64_t seed : {1, 2, 3}) {
      SimplifyOptions options;
      options.metric = "energy";
      options.target_ratio = 0.01;
      options.samples_per_face = 0.05;
      options.seed = seed;
      pooled.add(compare(name, repaired, options, {2, 4}));
    }
    expect_near_sequential(pooled, name, 1.6);
  }
}

// A double-sided sheet beside a sphere: the sheet's copies simplify only by seam collapses,
// which the rounds' edge samples cost as the jobs make them (round_shares.h), so that the
// sheet's subsets are asked for their share of the faces and the sphere's subsets are not
// left to remove the round's faces alone.
TEST(ParallelQuality, ADoubleSidedSheetTakesItsShareOfTheRounds) {
  const RepairedMesh repaired = repair_mesh(testing::double_sided_sheet_beside_a_sphere(40));
  for (const char* metric : {"quadric", "energy"}) {
    SimplifyOptions options;
    options.metric = metric;
    options.target_ratio = 0.02;
    const Ratios r = compare("double-sided sheet, sphere", repaired, options, {2, 4, 8});
    EXPECT_LE(median(r.rms), 1.10) << metric;
    EXPECT_LE(r.worst_rms, 1.35) << metric;
  }
}

// The round's faces divided by the jobs' cheap edges (ParallelOptions::cost_shares) against
// equal shares of their removable faces, at the level inside round 0 where they differ most:
// the energy coarsens fandisk's flat sides long before its curved parts, and equal shares make
// each of 8 jobs coarsen its region alike. The rounds are the geometric ones (border_excess 0),
// so that the 50% level lies inside round 0, whose shares this is about. The sequential 50%
// level is near exact (metro RMS about 6e-7 of the diagonal), so small differences are large
// ratios: measured 1.59 by cheap edges, 2.01 equal shares (issue 37's target, within 5% of the
// sequential level, is not met here). The guard's history: docs/DECISIONS.md, "Test guards".
TEST(ParallelQuality, SharesByCheapEdgesFollowTheSequentialOrder) {
  const std::filesystem::path path = shared_meshes_dir() / "fandisk-13k.obj";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "../shared/meshes is not present";
  const RepairedMesh repaired = repair_mesh(read_mesh(path.string()));
  const Mesh input = repaired_input(repaired);
  SimplifyOptions options;
  options.metric = "energy";
  const uint64_t half = repaired.mesh.face_count() / 2;
  auto rms_at_half = [&](const ProgressiveMesh& pm) {
    return surface_distance(input, level_of_detail(pm, level_for_faces(pm, half)), kSamples).rms;
  };
  const double sequential = rms_at_half(build_progressive_mesh(repaired, options));
  ParallelOptions parallel;
  parallel.subsets = 8;
  parallel.min_subset_faces = 0;  // 8 subsets (by default, 6 of its 13k faces)
  parallel.border_excess = 0;
  const double by_cheap_edges =
      rms_at_half(build_progressive_mesh_parallel(repaired, options, parallel)) / sequential;
  parallel.cost_shares = false;
  const double equal =
      rms_at_half(build_progressive_mesh_parallel(repaired, options, parallel)) / sequential;
  std::printf("fandisk-13k energy p=8 50%%: rms by cheap edges %.3f, equal shares %.3f\n",
              by_cheap_edges, equal);
  EXPECT_LE(by_cheap_edges, 1.8);
  EXPECT_LT(by_cheap_edges, equal);
}

}  // namespace
}  // namespace parapm::testing
