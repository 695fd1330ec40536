// The parallel construction end to end (engine/parallel/parallel_build.h) on real meshes: the
// PM is lossless, reaches the sequential build's target, does not depend on the thread count,
// equals the sequential PM for p = 1, and leaves no band of full-resolution faces along the
// subsets' borders at coarse levels.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "drawn_meshes.h"
#include "mesh/repaired_input.h"
#include "parallel/border_band.h"
#include "parallel/parallel_build.h"
#include "parallel_test_support.h"
#include "pm/mesh_compare.h"
#include "pm/pm_restore.h"
#include "simplify/simplify.h"

namespace parapm {
namespace {

SimplifyOptions metric_options(const std::string& metric, double ratio = 0) {
  SimplifyOptions options;
  options.metric = metric;
  options.target_ratio = ratio;
  return options;
}

ParallelOptions with_p(uint32_t p, unsigned threads = 0, uint32_t rounds = 3) {
  ParallelOptions parallel;
  parallel.subsets = p;
  parallel.threads = threads;
  parallel.rounds = rounds;
  // p subsets in every round: the committed meshes are small, and these tests are about the
  // rounds (SmallMeshesTakeFewerSubsets is about the cap).
  parallel.min_subset_faces = 0;
  return parallel;
}

void expect_lossless(const std::string& name, const std::string& metric, uint32_t p,
                     uint32_t rounds) {
  const auto start = std::chrono::steady_clock::now();
  const RepairedMesh repaired = testing::repaired_test_mesh(name);
  ParallelStats stats;
  const SimplifyOptions options = metric_options(metric);
  const ProgressiveMesh built =
      build_progressive_mesh_parallel(repaired, options, with_p(p, 0, rounds), &stats);
  // Through the file format, as a client gets it.
  std::istringstream in(testing::pm_bytes(built));
  const ProgressiveMesh pm = read_pm(in, name);
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
  EXPECT_TRUE(diff.equal) << name << " " << metric << " p=" << p << ": " << diff.first_difference;
  // The same target as the sequential build: as far as collapses stay legal.
  const ProgressiveMesh sequential = build_progressive_mesh(repaired, options);
  // With no target ("as far as legal") where collapses run out depends on the path: a
  // few faces either way, and a little more where seam collapses of the repair's copies hold
  // the legal minimum (the CAD part at p = 4: 2072 faces against 2048; stratocaster-9k's
  // 490-498 against 484).
  EXPECT_LE(pm.base.face_count(), sequential.base.face_count() * 103 / 100 + 2)
      << name << " " << metric << " p=" << p;
  // The scheduled rounds, and more where a round's border band bounded it (border_excess).
  uint32_t geometric = 0;
  for (const RoundStats& r : stats.round_stats) geometric += r.border_limited ? 0 : 1;
  ASSERT_GE(stats.round_stats.size(), rounds);
  EXPECT_LE(geometric, rounds);
  uint64_t parallel_collapses = 0;
  for (const RoundStats& r : stats.round_stats) {
    uint64_t round_collapses = 0;
    for (const SubsetTiming& s : r.subsets) round_collapses += s.collapses;
    EXPECT_GT(round_collapses, 0u) << name << " round " << r.round;
    EXPECT_LE(r.faces_after, r.faces_before) << name << " round " << r.round;
    parallel_collapses += round_collapses;
  }
  // The rounds went down to the handover (10% of the faces): the final pass does the last
  // tenth, and what the jobs' cost ceiling and the last borders left. One round, from all
  // faces to a tenth, stops at its cost ceiling well before.
  EXPECT_GT(parallel_collapses, (rounds > 1 ? 3 : 1) * stats.final_pass_collapses)
      << "most of the work is parallel";
  std::printf(
      "parallel %-7s p=%u R=%u (%zu done) %-36s %7zu faces -> base %5zu (sequential %5zu), "
      "%6llu collapses in subsets, %6llu in the final pass, %.2f s\n",
      metric.c_str(), p, rounds, stats.round_stats.size(), name.c_str(), repaired.mesh.face_count(),
      pm.base.face_count(), sequential.base.face_count(), (unsigned long long)parallel_collapses,
      (unsigned long long)stats.final_pass_collapses,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

TEST(ParallelBuild, LosslessWithTheQuadricMetric) {
  for (uint32_t p : {2u, 4u})
    for (uint32_t rounds : {1u, 2u, 3u}) {
      expect_lossless("stratocaster-9k.ply", "quadric", p, rounds);
      expect_lossless("pymeshlab-colored-airplane-11k.ply", "quadric", p, rounds);
    }
  expect_lossless("cad-cycloidal-43k.ply", "quadric", 4, 3);
}

TEST(ParallelBuild, LosslessWithTheEnergyMetric) {
  for (uint32_t p : {2u, 4u})
    for (uint32_t rounds : {2u, 3u}) {
      expect_lossless("stratocaster-9k.ply", "energy", p, rounds);
      expect_lossless("pymeshlab-colored-airplane-11k.ply", "energy", p, rounds);
    }
}

// Past the handover, extra rounds at the same ratio while the last round's jobs did what they
// were asked and the subsets stay above the floor: on the 20k-face vessel at p = 2 with a floor of
// 200 faces per subset, rounds beyond the three scheduled ones, each following a round that did at
// least 90% of its share, and a lossless PM whose final pass is shorter than without them. (The
// 43k CAD part's rounds stop at their cost ceiling short of their goals: it gets none.)
TEST(ParallelBuild, ExtraRoundsPastTheHandoverWhileTheyDoTheirShare) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  const SimplifyOptions options = metric_options("quadric", 0.005);
  ParallelOptions parallel = with_p(2);
  parallel.border_excess = 0;  // the scheduled rounds are then three (the bound adds rounds)
  parallel.extra_round_subset_faces = 200;
  ParallelStats extra, none;
  const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, parallel, &extra);
  parallel.extra_round_subset_faces = 0;
  build_progressive_mesh_parallel(repaired, options, parallel, &none);
  EXPECT_EQ(none.rounds, 3u);
  ASSERT_GT(extra.rounds, 3u);
  for (size_t r = 3; r < extra.round_stats.size(); ++r) {
    const RoundStats& before = extra.round_stats[r - 1];
    const RoundStats& round = extra.round_stats[r];
    EXPECT_GE(double(before.faces_before - before.faces_after), 0.5 * double(before.asked_faces))
        << "round " << r << " follows a round that did less than half of its share";
    EXPECT_GE(round.goal_faces, 2u * 200u) << "round " << r;
  }
  // Jobs are asked for the round's fraction of the faces they can remove: not their borders.
  for (const RoundStats& round : extra.round_stats) {
    EXPECT_GT(round.asked_faces, 0u) << "round " << round.round;
    EXPECT_LT(round.asked_faces, round.faces_before - round.goal_faces) << "round " << round.round;
  }
  EXPECT_LT(extra.final_pass_collapses, none.final_pass_collapses);
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
  EXPECT_TRUE(diff.equal) << diff.first_difference;
  std::printf(
      "gmsh-aneurysm-20k p=2: %u rounds (3 without extra rounds), final pass %llu "
      "collapses (%llu)\n",
      extra.rounds, (unsigned long long)extra.final_pass_collapses,
      (unsigned long long)none.final_pass_collapses);
}

// A quadric build of a committed mesh at p = 4 with an extra rounds' floor; its stats in
// `stats`.
ProgressiveMesh build_with_floor(const RepairedMesh& repaired, uint64_t floor,
                                 ParallelStats& stats) {
  ParallelOptions parallel = with_p(4);
  parallel.border_excess = 0;  // three scheduled rounds, then the extra ones
  parallel.extra_round_subset_faces = floor;
  return build_progressive_mesh_parallel(repaired, metric_options("quadric", 0.005), parallel,
                                         &stats);
}

// Past the handover, once p subsets would leave fewer faces each than the floor, the extra
// rounds go on with fewer subsets (at least two): the vessel at p = 4 with a floor of 400 gets
// a fourth round on 2 subsets, and a lossless PM.
TEST(ParallelBuild, ExtraRoundsNarrowToKeepTheFloor) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  ParallelStats stats;
  const ProgressiveMesh pm = build_with_floor(repaired, 400, stats);
  ASSERT_GT(stats.rounds, 3u);
  for (size_t r = 0; r < stats.round_stats.size(); ++r) {
    const RoundStats& round = stats.round_stats[r];
    const size_t subsets = round.subsets.size();
    if (r < 3) {
      EXPECT_EQ(subsets, 4u) << "round " << r;
      continue;
    }
    EXPECT_GE(subsets, 2u) << "round " << r;
    EXPECT_LT(subsets, 4u) << "round " << r << ": 4 subsets would hold fewer than 400 faces";
    EXPECT_GE(round.goal_faces, subsets * 400) << "round " << r;
  }
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
  EXPECT_TRUE(diff.equal) << diff.first_difference;
}

// After a round that did at least half of its share but less than 90% (its jobs stopped at
// their cost ceiling), an extra round still follows, on subsets of 2.5 times the floor: the
// CAD part at p = 4 with a floor of 600, whose third round does 72% of its share, gets a
// fourth round on 2 subsets of at least 1500 faces (4 of 600 with the floor alone).
TEST(ParallelBuild, ExtraRoundsAfterAShortRoundTakeLargerSubsets) {
  const RepairedMesh repaired = testing::repaired_test_mesh("cad-cycloidal-43k.ply");
  ParallelStats stats;
  const ProgressiveMesh pm = build_with_floor(repaired, 600, stats);
  ASSERT_GT(stats.rounds, 3u);
  bool after_short = false;
  for (size_t r = 3; r < stats.round_stats.size(); ++r) {
    const RoundStats& before = stats.round_stats[r - 1];
    const RoundStats& round = stats.round_stats[r];
    const double done = double(before.faces_before - before.faces_after);
    EXPECT_GE(done, 0.5 * double(before.asked_faces)) << "round " << r;
    const bool short_round = done < 0.9 * double(before.asked_faces);
    after_short = after_short || short_round;
    const size_t subsets = round.subsets.size();
    EXPECT_GE(subsets, 2u) << "round " << r;
    EXPECT_GE(round.goal_faces, subsets * (short_round ? 1500u : 600u)) << "round " << r;
  }
  EXPECT_TRUE(after_short) << "no extra round followed a short one: a weak test";
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
  EXPECT_TRUE(diff.equal) << diff.first_difference;
}

// Keys carried from round to round (edge_keys.h): with the energy, every round after the first
// gives its jobs most of their edges' keys, and the edges the last round's jobs left deferred;
// the jobs answer their first costing of the keys from them, and the PM stays lossless; without
// carrying, or with the quadric (whose costings are cheaper than carrying them), neither
// travels.
TEST(ParallelBuild, CarriedKeysSpareTheJobsTheirFirstCosting) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  ParallelOptions parallel = with_p(2);
  ParallelStats carried, keys_only, fresh, quadric;
  const ProgressiveMesh pm =
      build_progressive_mesh_parallel(repaired, metric_options("energy"), parallel, &carried);
  build_progressive_mesh_parallel(repaired, metric_options("quadric"), parallel, &quadric);
  parallel.carry_deferred = false;
  const ProgressiveMesh keys_only_pm =
      build_progressive_mesh_parallel(repaired, metric_options("energy"), parallel, &keys_only);
  parallel.carry_keys = false;
  build_progressive_mesh_parallel(repaired, metric_options("energy"), parallel, &fresh);
  // Each carried thing spares costings (the modules' own count, PriorityModule::costings):
  // every edge is costed at least once.
  EXPECT_LT(carried.costings, keys_only.costings);
  EXPECT_LT(keys_only.costings, fresh.costings);
  EXPECT_GT(carried.costings, repaired.mesh.face_count() * 3 / 2);
  std::printf(
      "costings: %llu with keys and deferred edges carried, %llu with keys only, %llu "
      "with neither\n",
      (unsigned long long)carried.costings, (unsigned long long)keys_only.costings,
      (unsigned long long)fresh.costings);
  for (const RoundStats& round : keys_only.round_stats)
    EXPECT_EQ(round.deferred_carried, 0u) << "round " << round.round;
  ASSERT_GE(carried.round_stats.size(), 2u);
  uint64_t deferred_carried = 0;
  for (size_t r = 1; r < carried.round_stats.size(); ++r) {
    const RoundStats& round = carried.round_stats[r];
    EXPECT_GT(round.keys_carried, round.faces_before / 2) << "round " << r;
    EXPECT_GE(round.keys_reused, round.keys_carried) << "round " << r;
    // (Only deferring rounds leave deferred edges, those above a tenth of the input's faces,
    // and a round's collapses may change every end its predecessor left deferred.)
    deferred_carried += round.deferred_carried;
    std::printf(
        "energy round %zu: %llu faces, %llu keys carried, %llu answered, %llu deferred "
        "edges carried\n",
        r, (unsigned long long)round.faces_before, (unsigned long long)round.keys_carried,
        (unsigned long long)round.keys_reused, (unsigned long long)round.deferred_carried);
  }
  EXPECT_GT(deferred_carried, 0u);
  for (const ParallelStats* none : {&fresh, &quadric})
    for (const RoundStats& round : none->round_stats) {
      EXPECT_EQ(round.keys_carried, 0u) << "round " << round.round;
      EXPECT_EQ(round.keys_reused, 0u) << "round " << round.round;
      EXPECT_EQ(round.deferred_carried, 0u) << "round " << round.round;
    }
  for (const ProgressiveMesh* built : {&pm, &keys_only_pm}) {
    const MeshDifference diff =
        compare_meshes_exact(restore_input(*built), repaired_input(repaired), false);
    EXPECT_TRUE(diff.equal) << diff.first_difference;
  }
}

TEST(ParallelBuild, TargetFaceCountIsReached) {
  const RepairedMesh repaired = testing::repaired_test_mesh("pymeshlab-bunny-textured-10k.obj");
  for (double ratio : {0.5, 0.1, 0.02}) {
    const SimplifyOptions options = metric_options("quadric", ratio);
    const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, with_p(3));
    const size_t target = target_face_count(repaired.mesh.face_count(), options);
    EXPECT_LE(pm.base.face_count(), target) << "ratio " << ratio;
    EXPECT_GE(pm.base.face_count() + 2, target) << "ratio " << ratio;
  }
}

// Three rounds, each on its own partition, with the state travelling.
TEST(ParallelBuild, SameBytesWhateverTheThreadCount) {
  const RepairedMesh repaired = testing::repaired_test_mesh("pymeshlab-colored-airplane-11k.ply");
  for (const char* metric : {"quadric", "energy"}) {
    SimplifyOptions options = metric_options(metric, 0.1);
    options.samples_per_face = std::string(metric) == "energy" ? 1 : 0;
    const std::string one = testing::pm_bytes(
        build_progressive_mesh_parallel(repaired, options, with_p(4, /*threads=*/1, 3)));
    const std::string again = testing::pm_bytes(
        build_progressive_mesh_parallel(repaired, options, with_p(4, /*threads=*/1)));
    const std::string four = testing::pm_bytes(
        build_progressive_mesh_parallel(repaired, options, with_p(4, /*threads=*/4)));
    EXPECT_TRUE(one == again) << metric;
    EXPECT_TRUE(one == four) << metric << ": the thread count changed the PM";
    options.seed = 2;
    if (std::string(metric) == "energy") {
      EXPECT_FALSE(one == testing::pm_bytes(
                              build_progressive_mesh_parallel(repaired, options, with_p(4, 4))))
          << "the seed draws other points";
    }
  }
}

// The band passes' and the final pass's collapses that move many points project them, list
// them and sum their moments on a team of threads (ParallelOptions::team_min_points), then cost
// the edges around them there, and so do the jobs of a round with fewer subsets than p, each on
// a team of its own: the same PM and the same costings whether every collapse does, none, or
// only the rich ones, on one thread or four; and lossless. With colours, the points go where
// their attributes fit too (E_scalar), and the edges are costed one after the other.
TEST(ParallelBuild, TheTeamsChangeNoByte) {
  for (const char* name : {"stratocaster-9k.ply", "pymeshlab-colored-airplane-11k.ply"}) {
    const RepairedMesh repaired = testing::repaired_test_mesh(name);
    SimplifyOptions options = metric_options("energy");
    options.samples_per_face = 4;
    auto build = [&](uint32_t on_team, unsigned threads, ParallelStats* stats = nullptr) {
      ParallelOptions parallel = with_p(4, threads);
      parallel.team_min_points = on_team;
      parallel.min_subset_faces = 2000;  // rounds of 4 subsets, and of fewer at the tail
      return build_progressive_mesh_parallel(repaired, options, parallel, stats);
    };
    ParallelStats alone, stats;
    const std::string none = testing::pm_bytes(build(0, 4, &alone));
    EXPECT_TRUE(testing::pm_bytes(build(1, 4, &stats)) == none)
        << name << ": every collapse on the team";
    EXPECT_EQ(stats.costings, alone.costings) << name;
    // (Rounds of fewer jobs than p: their jobs had teams.)
    EXPECT_TRUE(std::any_of(stats.round_stats.begin(), stats.round_stats.end(),
                            [](const RoundStats& r) { return r.subsets.size() < 4; }))
        << name;
    EXPECT_TRUE(testing::pm_bytes(build(1, 1)) == none) << name << ": on one thread";
    const ProgressiveMesh rich = build(64, 3);
    EXPECT_TRUE(testing::pm_bytes(rich) == none) << name << ": the rich ones on the team";
    const MeshDifference diff =
        compare_meshes_exact(restore_input(rich), repaired_input(repaired), false);
    EXPECT_TRUE(diff.equal) << name << ": " << diff.first_difference;
  }
}

// Partitions are drawn ahead: round 1's beside round 0's jobs (on the mesh as round 0 found
// it), every later one beside the band pass before it (on a copy of the mesh as it was before
// the band pass); a round takes it when it has as many subsets as foreseen. On two threads
// (really side by side) the PM is the one-thread PM and lossless. Without early_partition,
// round 1's is drawn after the merge, on the mesh round 0 left: another PM. One that would keep
// round 0's borders is drawn anew.
TEST(ParallelBuild, PartitionsAreDrawnAhead) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  const SimplifyOptions options = metric_options("energy", 0.01);
  std::string one_thread;
  for (unsigned threads : {1u, 2u}) {
    ParallelStats stats;
    const ProgressiveMesh pm = build_progressive_mesh_parallel(
        repaired, options, with_p(4, threads, /*rounds=*/0), &stats);
    size_t foreseen = 0, band_passes = 0;
    for (const RoundStats& r : stats.round_stats) {
      foreseen += r.partition_foreseen ? 1 : 0;
      EXPECT_EQ(r.partition_foreseen, r.round >= 1) << "round " << r.round;
      EXPECT_GE(r.partition_overlap_seconds, 0) << "round " << r.round;
      EXPECT_LE(r.partition_overlap_seconds, r.partition_seconds + r.append_seconds)
          << "round " << r.round;
      band_passes += r.round >= 1 ? 1 : 0;
    }
    ASSERT_GE(band_passes, 2u) << "threads " << threads;
    EXPECT_GE(foreseen, band_passes) << "threads " << threads;
    const std::string bytes = testing::pm_bytes(pm);
    if (threads == 1) one_thread = bytes;
    EXPECT_TRUE(bytes == one_thread) << "threads " << threads;
    std::istringstream in(bytes);
    const MeshDifference diff = compare_meshes_exact(restore_input(read_pm(in, "foreseen")),
                                                     repaired_input(repaired), false);
    EXPECT_TRUE(diff.equal) << diff.first_difference;
  }
  ParallelOptions late = with_p(4, 2, /*rounds=*/0);
  late.early_partition = false;
  ParallelStats stats;
  const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, late, &stats);
  ASSERT_GE(stats.round_stats.size(), 2u);
  EXPECT_FALSE(stats.round_stats[1].partition_foreseen);
  EXPECT_FALSE(testing::pm_bytes(pm) == one_thread);

  // The stratocaster's round 1 partition drawn beside round 0's jobs is round 0's again (the
  // same mesh, the same start vertex): refused, drawn anew after the merge, round 0's records
  // still in the PM.
  const RepairedMesh guitar = testing::repaired_test_mesh("stratocaster-9k.ply");
  ParallelStats guitar_stats;
  const ProgressiveMesh redrawn =
      build_progressive_mesh_parallel(guitar, options, with_p(4, 2, /*rounds=*/0), &guitar_stats);
  ASSERT_GE(guitar_stats.round_stats.size(), 2u);
  EXPECT_FALSE(guitar_stats.round_stats[1].partition_foreseen);
  std::istringstream again(testing::pm_bytes(redrawn));
  const MeshDifference guitar_diff =
      compare_meshes_exact(restore_input(read_pm(again, "redrawn")), repaired_input(guitar), false);
  EXPECT_TRUE(guitar_diff.equal) << guitar_diff.first_difference;
}

// The final pass on a compact copy of the live mesh (live_pass.h) makes the PM and the
// costings the pass on the whole mesh's arrays makes, with either metric (the energy's points,
// keys and deferred edges carried over): on a mesh with attributes, on one whose repair made
// copies (seam collapses, its rims' copies locked), and on a scene whose small parts vanish in
// the final pass.
TEST(ParallelBuild, TheFinalPassOnALiveCopyChangesNoByte) {
  struct Case {
    const char* what;
    RepairedMesh repaired;
    uint64_t target_faces;
  };
  std::vector<Case> cases;
  cases.push_back(
      {"airplane", testing::repaired_test_mesh("pymeshlab-colored-airplane-11k.ply"), 200});
  cases.push_back({"double-sided sheet",
                   repair_mesh(testing::double_sided(testing::book_of_sheets(1, 24, 6))), 40});
  cases.push_back({"ground with patches", repair_mesh(testing::ground_with_patches(150)), 40});
  ASSERT_GT(cases[1].repaired.report.vertex_copies_added, 0u);
  for (const char* metric : {"quadric", "energy"})
    for (const Case& c : cases) {
      SimplifyOptions options = metric_options(metric);
      options.target_faces = c.target_faces;
      ParallelOptions parallel = with_p(4);
      ParallelStats on_copy, on_whole;
      const std::string copied = testing::pm_bytes(
          build_progressive_mesh_parallel(c.repaired, options, parallel, &on_copy));
      parallel.final_pass_on_live_copy = false;
      const ProgressiveMesh whole =
          build_progressive_mesh_parallel(c.repaired, options, parallel, &on_whole);
      EXPECT_TRUE(on_copy.final_pass_on_live_copy) << metric << " " << c.what;
      EXPECT_FALSE(on_whole.final_pass_on_live_copy) << metric << " " << c.what;
      EXPECT_GT(on_copy.final_pass_collapses, 0u) << metric << " " << c.what;
      EXPECT_EQ(on_copy.final_pass_collapses, on_whole.final_pass_collapses)
          << metric << " " << c.what;
      EXPECT_EQ(on_copy.costings, on_whole.costings) << metric << " " << c.what;
      EXPECT_TRUE(copied == testing::pm_bytes(whole))
          << metric << " " << c.what << ": the PMs differ";
      std::printf("%s, %s: %zu faces, final pass %llu collapses to %zu faces\n", metric, c.what,
                  c.repaired.mesh.face_count(), (unsigned long long)on_copy.final_pass_collapses,
                  whole.base.face_count());
    }
}

// With one subset nothing is a border: the job is the whole mesh and runs the sequential
// queue to the handover; the final pass then continues from the same metric state with a
// fresh queue. Both metrics' costs depend on the star around the edge (the quadric's through
// the constraints its placement meets): the sequential queue keeps entries whose stars changed
// since (a known approximation of the driver), the fresh queue re-costs them, so the PMs agree
// exactly up to the handover, the energy's only without deferred re-costing (with it they
// part after a few hundred collapses on the airplane: the job's cost ceiling refuses edges
// that the sequential build keys, so the two defer different edges).
TEST(ParallelBuild, OneSubsetGivesTheSequentialPmUpToTheHandover) {
  for (const char* name : {"stratocaster-9k.ply", "pymeshlab-colored-airplane-11k.ply"})
    for (const char* metric : {"quadric", "energy"}) {
      const RepairedMesh repaired = testing::repaired_test_mesh(name);
      SimplifyOptions options = metric_options(metric);
      options.defer_recosting = false;
      ParallelStats stats;
      const ProgressiveMesh parallel =
          build_progressive_mesh_parallel(repaired, options, with_p(1), &stats);
      const ProgressiveMesh sequential = build_progressive_mesh(repaired, options);
      const size_t before_handover = stats.round_stats.at(0).subsets.at(0).collapses;
      ASSERT_GT(before_handover, parallel.splits.size() / 3);  // a large part of the build
      ASSERT_GE(sequential.splits.size(), before_handover);
      // Collapse i is split n - 1 - i.
      for (size_t i = 0; i < before_handover; ++i) {
        const VertexSplit& a = parallel.splits[parallel.splits.size() - 1 - i];
        const VertexSplit& b = sequential.splits[sequential.splits.size() - 1 - i];
        ASSERT_TRUE(a.vs_after == b.vs_after && a.vt_after == b.vt_after &&
                    a.vs_before == b.vs_before)
            << name << ": " << metric << " collapse " << i << " of " << before_handover;
      }
    }
}

// The 1999 build's weakness: faces along the borders stayed at full resolution. Each round
// partitions the current mesh anew, so a round's border lies inside the next round's subsets,
// whose cheap collapses take it first; the final pass takes what the last borders kept. At
// 10% and 2% of the faces the level holds as many input faces as the sequential one. (At the
// end of the first round the band is there by design: the measure must see it.)
TEST(ParallelBuild, NoBandOfFullResolutionFacesAtCoarseLevels) {
  for (const char* metric : {"quadric", "energy"}) {
    // Simplifies to 4 faces: the 2% level is a level of the PM, not its base mesh.
    const RepairedMesh repaired = testing::repaired_test_mesh("pymeshlab-colored-airplane-11k.ply");
    const SimplifyOptions options = metric_options(metric);
    const ProgressiveMesh sequential = build_progressive_mesh(repaired, options);
    const size_t full = repaired.mesh.face_count();
    for (uint32_t p : {1u, 2u, 4u}) {
      ParallelStats stats;
      const ProgressiveMesh pm =
          build_progressive_mesh_parallel(repaired, options, with_p(p), &stats);
      for (const RoundStats& r : stats.round_stats) {
        const LevelBand seq = original_faces_at(sequential, r.faces_after);
        const LevelBand par = original_faces_at(pm, r.faces_after);
        std::printf(
            "%-7s p=%u end of round %u (%5zu faces): input faces sequential %4zu, "
            "parallel %4zu\n",
            metric, p, r.round, par.faces, seq.original_faces, par.original_faces);
      }
      for (size_t percent : {10u, 2u}) {
        const LevelBand seq = original_faces_at(sequential, full * percent / 100);
        const LevelBand par = original_faces_at(pm, full * percent / 100);
        std::printf(
            "%-7s band at %2zu%%: sequential %4zu of %5zu faces are input faces, p=%u "
            "%4zu of %5zu\n",
            metric, percent, seq.original_faces, seq.faces, p, par.original_faces, par.faces);
        EXPECT_EQ(par.original_faces, seq.original_faces) << metric << " p=" << p;
      }
      // An unfinished border would show here: a round leaves input faces along its cut. With
      // rounds bounded by their border band (the default) the first round ends with about
      // as many input faces as the sequential level, so the measure is checked on the
      // geometric rounds, whose first round goes down to a third, at p = 4 (4423 against
      // 4306 input faces, quadric; at p = 2 one cut's band is within the level's noise:
      // 2132 against 2133 in the repair's spatial order).
      if (p == 4) {
        ParallelOptions geometric = with_p(p);
        geometric.border_excess = 0;
        ParallelStats geometric_stats;
        const ProgressiveMesh unbounded =
            build_progressive_mesh_parallel(repaired, options, geometric, &geometric_stats);
        const uint64_t first = geometric_stats.round_stats.at(0).faces_after;
        EXPECT_GT(original_faces_at(unbounded, first).original_faces,
                  original_faces_at(sequential, first).original_faces)
            << "the measure sees the band at the end of the first round";
      }
    }
  }
}

// The first step's path, the master re-running collapsed() on every merged record instead of
// importing the jobs' states, still gives a lossless PM to the same target; it costs the
// master more (the replay re-projects every point).
TEST(ParallelBuild, ReplayedStateAlsoGivesALosslessPm) {
  const RepairedMesh repaired = testing::repaired_test_mesh("stratocaster-9k.ply");
  const SimplifyOptions options = metric_options("energy", 0.2);
  ParallelOptions replayed = with_p(3);
  replayed.replay_state = true;
  ParallelStats replay_stats, import_stats;
  const ProgressiveMesh a =
      build_progressive_mesh_parallel(repaired, options, replayed, &replay_stats);
  const ProgressiveMesh b =
      build_progressive_mesh_parallel(repaired, options, with_p(3), &import_stats);
  for (const ProgressiveMesh* pm : {&a, &b}) {
    std::istringstream in(testing::pm_bytes(*pm));
    const MeshDifference diff = compare_meshes_exact(restore_input(read_pm(in, "replayed")),
                                                     repaired_input(repaired), false);
    EXPECT_TRUE(diff.equal) << diff.first_difference;
    EXPECT_LE(pm->base.face_count(), target_face_count(repaired.mesh.face_count(), options));
  }
  // The first round is the same either way (its jobs import the same master state).
  ASSERT_FALSE(replay_stats.round_stats.empty());
  EXPECT_EQ(replay_stats.round_stats[0].faces_after, import_stats.round_stats[0].faces_after);
}

TEST(ParallelBuild, BadOptionsAreErrors) {
  const RepairedMesh repaired = testing::repaired_test_mesh("stratocaster-9k.ply");
  EXPECT_THROW(build_progressive_mesh_parallel(repaired, {}, with_p(0)), Error);
  EXPECT_THROW(build_progressive_mesh_parallel(repaired, {}, with_p(257)), Error);
  ParallelOptions handover = with_p(2);
  handover.handover_ratio = 0;
  EXPECT_THROW(build_progressive_mesh_parallel(repaired, {}, handover), Error);
  EXPECT_THROW(build_progressive_mesh_parallel(repaired, {}, with_p(2, 0, 65)), Error);
  EXPECT_THROW(build_progressive_mesh_parallel(repaired, metric_options("nope"), with_p(2)), Error);
}

// Rounds bounded by their border band (ParallelOptions::border_excess): each bounded round
// ends where its band holds at most border_excess x its faces in excess of the rest's
// resolution, or removes its 15% (at p = 8 a fifth of this 20k-face mesh is band), and more
// rounds than scheduled follow; the band a round leaves is taken by the next, so at 50% of
// the faces fewer input faces remain than with the geometric rounds, whose first round runs
// past 50% with its band untouched.
TEST(ParallelBuild, RoundsBoundedByTheirBorderBand) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  const SimplifyOptions options = metric_options("energy", 0.01);
  for (uint32_t p : {2u, 8u}) {
    ParallelOptions bounded = with_p(p, 0, /*rounds=*/0);
    ASSERT_GT(bounded.border_excess, 0);
    ParallelStats stats;
    const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, bounded, &stats);
    size_t limited = 0;
    for (const RoundStats& r : stats.round_stats) {
      if (!r.border_limited) continue;
      ++limited;
      const double before = double(r.faces_before), goal = double(r.goal_faces);
      const double excess = double(r.border_faces) * (before - goal) / before;
      EXPECT_TRUE(excess <= bounded.border_excess * goal * 1.001 || goal >= 0.85 * before - 1)
          << "p = " << p << " round " << r.round;
      EXPECT_LT(goal, before) << "p = " << p << " round " << r.round;
    }
    EXPECT_GT(limited, 0u) << "p = " << p;
    EXPECT_GT(stats.round_stats.size(), size_t(default_rounds(p))) << "p = " << p;
    const MeshDifference diff =
        compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
    EXPECT_TRUE(diff.equal) << "p = " << p << ": " << diff.first_difference;

    ParallelOptions geometric = bounded;
    geometric.border_excess = 0;
    const ProgressiveMesh unbounded = build_progressive_mesh_parallel(repaired, options, geometric);
    const size_t half = repaired.mesh.face_count() / 2;
    const size_t bounded_inputs = original_faces_at(pm, half).original_faces;
    const size_t geometric_inputs = original_faces_at(unbounded, half).original_faces;
    std::printf("p=%u: input faces at 50%%: %zu bounded (%zu rounds), %zu geometric\n", p,
                bounded_inputs, stats.round_stats.size(), geometric_inputs);
    EXPECT_LT(bounded_inputs, geometric_inputs) << "p = " << p;
  }
}

// Builds with `parallel` and checks that every round kept `floor` faces a subset: round 0 cut
// in (faces / floor) subsets, every round in 2 or more and at most (its faces / floor); and the
// PM lossless.
ParallelStats build_with_floor(const RepairedMesh& repaired, const SimplifyOptions& options,
                               const ParallelOptions& parallel, uint64_t floor) {
  ParallelStats stats;
  const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, parallel, &stats);
  if (stats.round_stats.empty()) return stats;
  EXPECT_EQ(stats.round_stats[0].subsets.size(), repaired.mesh.face_count() / floor);
  for (const RoundStats& r : stats.round_stats) {
    EXPECT_GE(r.subsets.size(), 2u) << "round " << r.round;
    EXPECT_LE(r.subsets.size(), r.faces_before / floor) << "round " << r.round;
  }
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
  EXPECT_TRUE(diff.equal) << diff.first_difference;
  return stats;
}

// A round cuts the mesh into at most (its faces / min_subset_faces) subsets: the 20k-face
// vessel at p = 16 gets 5 subsets in its first round (the energy's floor, 4000 faces a
// subset) and fewer as it shrinks (never below 2), and it takes fewer rounds (each of fixed
// work: partition, extraction, merge) than with 16 subsets of 1.2k faces, a fifth of which are
// border band.
TEST(ParallelBuild, SmallMeshesTakeFewerSubsets) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  const SimplifyOptions options = metric_options("energy", 0.01);
  ParallelOptions capped;  // the defaults: the energy's floor
  capped.subsets = 16;
  ASSERT_EQ(capped.min_subset_faces, kByMetric);
  const uint64_t floor = subset_faces_by_metric(true);
  const ParallelStats stats = build_with_floor(repaired, options, capped, floor);
  ASSERT_FALSE(stats.round_stats.empty());

  ParallelStats uncapped_stats;
  ParallelOptions uncapped = capped;
  uncapped.min_subset_faces = 0;
  build_progressive_mesh_parallel(repaired, options, uncapped, &uncapped_stats);
  EXPECT_EQ(uncapped_stats.round_stats[0].subsets.size(), 16u);
  std::printf("gmsh-aneurysm-20k p=16: %zu rounds capped (first on %zu subsets), %zu with 16\n",
              stats.round_stats.size(), stats.round_stats[0].subsets.size(),
              uncapped_stats.round_stats.size());
  EXPECT_LT(stats.round_stats.size(), uncapped_stats.round_stats.size());
}

// The quadric's subsets hold twice the energy's faces (subset_faces_by_metric): its work per
// face is a tenth of the energy's, a round's fixed work per face the same. The 20k-face vessel
// at p = 16 gets 2 subsets in its first round, not 5, and fewer rounds; given the energy's
// floor explicitly, the quadric gets the energy's subsets.
TEST(ParallelBuild, TheQuadricsSubsetsHoldMoreFaces) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  const SimplifyOptions options = metric_options("quadric", 0.01);
  const uint64_t floor = subset_faces_by_metric(false);
  ASSERT_EQ(floor, 2 * subset_faces_by_metric(true));
  ParallelOptions by_metric;  // the defaults
  by_metric.subsets = 16;
  const ParallelStats stats = build_with_floor(repaired, options, by_metric, floor);
  ASSERT_FALSE(stats.round_stats.empty());

  ParallelStats energy_floor_stats;
  ParallelOptions energy_floor = by_metric;
  energy_floor.min_subset_faces = subset_faces_by_metric(true);
  build_progressive_mesh_parallel(repaired, options, energy_floor, &energy_floor_stats);
  EXPECT_EQ(energy_floor_stats.round_stats[0].subsets.size(),
            repaired.mesh.face_count() / subset_faces_by_metric(true));
  std::printf(
      "gmsh-aneurysm-20k quadric p=16: %zu rounds by the metric, %zu with the energy's "
      "floor\n",
      stats.round_stats.size(), energy_floor_stats.round_stats.size());
  EXPECT_LT(stats.round_stats.size(), energy_floor_stats.round_stats.size());
}

// A round whose jobs removed less than a tenth of their share ends the rounds (plan_round):
// on a scene of 4096 closed tetrahedra every part is at its minimum, no collapse is legal,
// and rounds on new partitions would only extract and cost the mesh again (on such a mesh
// three did, at 6-9x the sequential build's CPU). One round, then the final pass, and the
// sequential build's PM.
TEST(ParallelBuild, AStuckMeshEndsTheRounds) {
  Mesh scene;
  for (int i = 0; i < 4096; ++i) {
    const double x = 2.0 * (i % 64), y = 2.0 * (i / 64);
    const auto base = VertexId(scene.positions.size());
    for (const Vec3& corner : {Vec3{x, y, 0}, Vec3{x + 1, y, 0}, Vec3{x, y + 1, 0}, Vec3{x, y, 1}})
      scene.positions.push_back(corner);
    for (const Triangle& t :
         {Triangle{0, 2, 1}, Triangle{0, 1, 3}, Triangle{1, 2, 3}, Triangle{2, 0, 3}})
      scene.faces.push_back({base + t[0], base + t[1], base + t[2]});
  }
  const RepairedMesh repaired = repair_mesh(scene);
  const SimplifyOptions options = metric_options("energy", 0.01);
  ParallelOptions parallel;  // the defaults: 3 scheduled rounds at p = 4
  parallel.subsets = 4;
  ParallelStats stats;
  const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, parallel, &stats);
  ASSERT_EQ(stats.round_stats.size(), 1u);
  EXPECT_GE(stats.round_stats[0].subsets.size(), 2u);
  EXPECT_EQ(stats.round_stats[0].faces_after, stats.round_stats[0].faces_before);
  EXPECT_EQ(testing::pm_bytes(pm), testing::pm_bytes(build_progressive_mesh(repaired, options)));
}

// Past the handover, the extra rounds step evenly to the target, each aiming to remove at least
// 15% of its faces, and the last one aims at the target (stepping by the scheduled ratio and
// stopping at the target can end on slivers: rounds of fixed work for a few faces). The vessel
// at p = 2 with a floor of 200 faces a subset and a target of 2%.
TEST(ParallelBuild, ExtraRoundsStepEvenlyToTheTarget) {
  const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
  const SimplifyOptions options = metric_options("quadric", 0.02);
  ParallelOptions parallel = with_p(2, 0, /*rounds=*/0);
  parallel.extra_round_subset_faces = 200;
  ParallelStats stats;
  const ProgressiveMesh pm = build_progressive_mesh_parallel(repaired, options, parallel, &stats);
  const uint64_t input = repaired.mesh.face_count();
  const uint64_t handover = uint64_t(std::llround(parallel.handover_ratio * double(input)));
  const uint64_t target = uint64_t(std::llround(0.02 * double(input)));
  const RoundStats* last_extra = nullptr;
  for (const RoundStats& round : stats.round_stats) {
    if (round.faces_before > handover) continue;  // a scheduled round
    last_extra = &round;
    EXPECT_LE(double(round.goal_faces), 0.85 * double(round.faces_before))
        << "round " << round.round << " aims at " << round.goal_faces << " of "
        << round.faces_before << " faces";
  }
  ASSERT_NE(last_extra, nullptr) << "no extra round: a weak test";
  EXPECT_EQ(last_extra->goal_faces, target);
  // (a collapse removes up to two faces: the last may land one below)
  EXPECT_LE(pm.base.face_count(), target);
  EXPECT_GE(pm.base.face_count() + 1, target);
  const MeshDifference diff =
      compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
  EXPECT_TRUE(diff.equal) << diff.first_difference;
}

// Rounds 0 (the default) schedules them by p: two at p = 2, three above (default_rounds).
TEST(ParallelBuild, DefaultRoundsFollowP) {
  const RepairedMesh repaired = testing::repaired_test_mesh("stratocaster-9k.ply");
  for (uint32_t p : {2u, 4u}) {
    ParallelOptions parallel = with_p(p, 0, /*rounds=*/0);
    parallel.extra_round_subset_faces = 0;  // the scheduled rounds only
    parallel.border_excess = 0;             // none shortened by its border band
    ParallelStats stats;
    const ProgressiveMesh pm = build_progressive_mesh_parallel(
        repaired, metric_options("quadric", 0.05), parallel, &stats);
    EXPECT_EQ(stats.rounds, p == 2 ? 2u : 3u) << "p = " << p;
    EXPECT_EQ(stats.rounds, default_rounds(p));
    const MeshDifference diff =
        compare_meshes_exact(restore_input(pm), repaired_input(repaired), false);
    EXPECT_TRUE(diff.equal) << "p = " << p << ": " << diff.first_difference;
  }
}

}  // namespace
}  // namespace parapm
