// Quality of the parallel PM against the sequential PM of the same metric: at 50%, 10% and 2%
// of the input faces and at the sequential base's size, the surface distance of the parallel
// level to the input (RMS and Hausdorff, both directions, engine/measure) over the sequential
// level's. Real meshes, all also in ../shared/meshes: a CAD part, a scanned vessel, the
// textured bunny; p = 2, 4, 8, 16 with quadrics, p = 2, 4 with the energy. Every figure is
// printed.
//
// What is asserted, per mesh and metric, as regression guards at today's figures with a
// margin: the median RMS ratio over the (p, level) cells within 10% (2026-11-21: 1.00-1.02 on
// the CAD part and the vessel, 1.06 on the bunny; the energy's, pooled over three draws of
// extra points, 2026-11-22: 0.98 on the vessel, 1.0 on the bunny), the median of the 10% cells
// alone (the level the rounds hand over at) within 10% (2026-11-22, since the jobs' shares of
// their removable faces: 0.99-1.06; 1.08-1.09 on the vessel before; 2026-11-25, since the
// repair's spatial order and the greedy partitioner's settled faces: 1.08 on the bunny, 1.00
// on the vessel, while the 18 meshes' 10% geometric mean stayed 1.00 at p = 4 and 16:
// docs/decisions/notebook-2026-11.md, "Memory order"), the worst cells under RMS
// 1.35 (the energy's pooled cells: 1.6, as single cells of the bunny's 2% level range over
// 0.84-1.45 from one draw to the next) and Hausdorff 2.6. Issue 5's target, every cell within
// 5% (RMS) and 10% (Hausdorff), is NOT met on these small meshes (at p = 16 the bunny's
// subsets hold 600 faces; worst cells 2026-11-21: RMS 1.29, Hausdorff 2.49; with the energy
// the bunny's 10% level was 1.17-1.34 in every draw; since the simplifier's requeue and the
// carried keys, 2026-11-22, it is 0.99-1.05, but its 2% and base levels 0.90-1.37; since the
// springs' scale the vessel's 10% level, the rounds' handover, was 1.05-1.13, since the
// shares of removable faces 0.99-1.02); it is on the 203k dragon
// (docs/decisions/notebook-2026-11.md, bench/parallel.sh with metro). One more test, on fandisk
// from ../shared/meshes, checks the jobs' shares by cheap edges against equal shares at the 50%
// level.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>

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

void expect_near_sequential(const Ratios& r, const std::string& name, double worst_rms = 1.35) {
  EXPECT_LE(median(r.rms), 1.10) << name;
  EXPECT_LE(median(r.handover_rms), 1.10) << name << ": the rounds' last level is uneven";
  EXPECT_LE(r.worst_rms, worst_rms) << name;
  EXPECT_LE(r.worst_hausdorff, 2.6) << name;
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
// 3k faces: locked copies of non-manifold vertices), so it is the base, whose last hundred
// collapses, the dearest legal ones, double its error; which of them remain moves with the
// rounds. At p = 16, 2026-11-24: 0.98 / 1.16 / 1.36 / 1.35 with border_excess 0 / 0.02 / 0.05
// (the default) / 0.1, while its 3100-face level is 0.98 / - / 1.03 / -. At p = 8, 2026-11-25,
// metro on the CLI's builds (default subsets), over six settings (rounds 2, 3 (the default),
// 4; border_excess 0.02, 0.1, 0): 1.04 / 1.05 / 1.28 / 1.00 / 1.04 / 1.04 with the edge
// sample costed on the master, 1.01 / 1.44 / 1.27 / 1.06 / 1.03 / 1.03 with the jobs costing
// their own samples (this test's cell: 1.04 -> 1.46): the same spread, another draw at the
// default.
TEST(ParallelQuality, QuadricLevelsMatchTheSequentialOnes) {
  for (const char* name :
       {"cad-cycloidal-43k.ply", "gmsh-aneurysm-20k.stl.gz", "pymeshlab-bunny-textured-10k.obj"}) {
    SimplifyOptions options;
    options.target_ratio = 0.01;
    expect_near_sequential(compare(name, repaired_test_mesh(name), options, {2, 4, 8, 16}), name,
                           name == std::string("cad-cycloidal-43k.ply") ? 1.5 : 1.35);
  }
}

// Pooled over three draws of extra points: on a 10k-face mesh one draw moves single cells by
// +-25% (the bunny's 2% level: RMS 0.040-0.054 sequential, 0.85-1.26 the ratio), so one run's
// median says more about the draw than about the build.
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

// The round's faces divided by the jobs' cheap edges (ParallelOptions::cost_shares) against
// equal shares of their removable faces, at the level inside round 0 where they differ most:
// with the energy's keys the sequential build coarsens fandisk's flat sides long before its
// curved parts, and equal shares made each of 8 jobs coarsen its region alike (metro RMS at
// 50%, 2026-11-22: 1.29 of the sequential level's in three draws, 0.99 by cheap edges).
// Since the energy's star planes (energy_priority.h) the sequential level is 5x closer to the
// input (RMS 8.3e-6 against 4.1e-5): its flat sides now cost nothing at all, and a round
// cannot take the flat faces along its borders, so the jobs take costlier ones inside
// instead: 1.11 by cheap edges, 1.30 equal shares (1.01 at p = 2, 1.23 at p = 16; the
// parallel level is still 4x closer than the sequential one was;
// docs/decisions/notebook-2026-11.md). The rounds are the geometric ones (border_excess 0), so that
// the 50% level lies inside round 0, whose shares this is about: rounds bounded by their border
// band put it in round 2 of 14, where it is 1.17 by cheap edges and 1.16 equal shares (fandisk's
// near-exact 50% level is the one the bound does not help: docs/decisions/notebook-2026-11.md,
// "Rounds bounded by their border band"). Since the greedy partitioner counts settled faces
// (2026-11-25), 8 subsets of fandisk are cut elsewhere: 1.18-1.19 by cheap edges, 1.27-1.36 equal
// shares, in the input's numbering and in the repair's spatial order alike. Since the energy's
// springs left its cost (2026-11-26, docs/DECISIONS.md) the sequential 50% level is near exact
// (metro RMS 5.9e-7 against 8.3e-6 before, 2.1x CGAL Lindstrom-Turk's): 1.65 by cheap edges, 2.12
// equal shares, the parallel level about 10x closer to the input than before; the bound follows
// (issue 37's target, within 5% of the sequential level, is not met here).
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
