// What a round asks of its jobs (engine/parallel/round_shares.h): the edge sample, taken by each
// job's own module in the extraction's tasks, and the water level and cheap-edge fractions
// drawn from it, each sampled edge weighted by the edges it stands for.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <vector>

#include "drawn_meshes.h"
#include "parallel/job_codec.h"
#include "parallel/round_shares.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_rule.h"
#include "parallel_test_support.h"
#include "simplify/copy_groups.h"
#include "simplify/simplifier.h"

namespace parapm {
namespace {

void expect_same_records(const std::vector<CollapseRecord>& a, const std::vector<CollapseRecord>& b,
                         const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].vs, b[i].vs) << what << " record " << i;
    ASSERT_EQ(a[i].vt, b[i].vt) << what << " record " << i;
    ASSERT_EQ(std::memcmp(&a[i].cost, &b[i].cost, sizeof(double)), 0) << what << " record " << i;
    for (int k = 0; k < 3; ++k) ASSERT_EQ(a[i].position[k], b[i].position[k]) << what;
  }
}

// Each job of the energy's round 0 in three subsets, on two meshes, asked for 60% of its
// faces; `what` names it.
void each_energy_job(
    const std::function<void(testing::RoundZero&, SubsetJob&, const std::string& what)>& body) {
  for (const char* name : {"stratocaster-9k.ply", "pymeshlab-colored-airplane-11k.ply"}) {
    SimplifyOptions options;
    options.metric = "energy";
    testing::RoundZero round(name, options, 3);
    for (SubsetJob& job : round.jobs) {
      job.options.target_faces = job.mesh.face_count() * 2 / 5;
      body(round, job, std::string(name) + " subset " + std::to_string(job.subset));
    }
  }
}

// The sampled edges with two free ends join the job's keys. They are the job's own costs (its
// module is imported from the same state), so the job given them makes the run it makes without
// them, answering those costings from the keys. Half the fresh keys are carried in, so that the
// sample answers some edges from them too.
TEST(RoundShares, SampledKeysGiveTheJobsOwnRun) {
  each_energy_job([](testing::RoundZero& round, SubsetJob& job, const std::string& what) {
    const std::vector<EdgeKey> fresh = testing::fresh_keys(*round.master, round.whole, job);
    std::vector<EdgeKey> half;
    for (size_t i = 0; i < fresh.size(); i += 2) half.push_back(fresh[i]);
    job.keys = half;
    SubsetJob sampled = job;
    const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
    const SubsetSample sample = sample_subset(sampled, free, true, sampled.keys);
    EXPECT_GT(sample.inner_edges, sample.costs.size()) << what;
    EXPECT_GE(sample.costs.size(), std::min<uint64_t>(sample.inner_edges, 1000)) << what;
    ASSERT_GT(sampled.keys.size(), half.size()) << what;
    // Every key once, sorted, each an edge with two free ends costed as the master costs it.
    for (size_t i = 0; i < sampled.keys.size(); ++i) {
      const EdgeKey& k = sampled.keys[i];
      ASSERT_TRUE(free[k.a] && free[k.b]) << what;
      if (i > 0) {
        const EdgeKey& before = sampled.keys[i - 1];
        ASSERT_TRUE(before.a < k.a || (before.a == k.a && before.b < k.b)) << what;
      }
      const auto it = std::lower_bound(
          fresh.begin(), fresh.end(), k,
          [](const EdgeKey& x, const EdgeKey& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
      ASSERT_TRUE(it != fresh.end() && it->a == k.a && it->b == k.b) << what;
      ASSERT_TRUE(it->cost == k.cost || (std::isnan(it->cost) && std::isnan(k.cost))) << what;
    }
    const SubsetResult with_sample = simplify_subset(sampled);
    const SubsetResult without = simplify_subset(job);
    expect_same_records(with_sample.records, without.records, what);
    EXPECT_GT(with_sample.keys_reused, without.keys_reused) << what;
  });
}

// A job given the mesh and metric its sample was costed on (PreparedSubset), its state dropped
// as the build drops it, makes the run it makes importing its state itself: the same records,
// keys, deferred edges, state and costings.
TEST(RoundShares, TheSamplesMetricRunsTheJobAsItsOwnImport) {
  each_energy_job([](testing::RoundZero&, SubsetJob& job, const std::string& what) {
    const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
    SubsetJob imports = job;
    sample_subset(imports, free, true, imports.keys);
    SubsetJob takes = job;
    PreparedSubset prepared;
    sample_subset(takes, free, true, takes.keys, &prepared);
    ASSERT_TRUE(prepared.metric && prepared.imported) << what;
    takes.state = MetricState{};
    SubsetResult own = simplify_subset(std::move(imports));
    SubsetResult taken =
        simplify_subset(std::move(takes), {}, nullptr, nullptr, {}, std::move(prepared));
    expect_same_records(taken.records, own.records, what);
    ASSERT_EQ(taken.keys.size(), own.keys.size()) << what;
    for (size_t i = 0; i < own.keys.size(); ++i) {
      ASSERT_EQ(taken.keys[i].a, own.keys[i].a) << what;
      ASSERT_EQ(taken.keys[i].b, own.keys[i].b) << what;
      ASSERT_EQ(std::memcmp(&taken.keys[i].cost, &own.keys[i].cost, sizeof(double)), 0) << what;
    }
    ASSERT_EQ(taken.deferred.size(), own.deferred.size()) << what;
    EXPECT_EQ(taken.costings, own.costings) << what;
    EXPECT_FALSE(own.state.empty()) << what;
    for (SubsetResult* r : {&own, &taken})
      r->wall_seconds = r->cpu_seconds = r->team_saved_seconds = r->team_cpu_seconds = 0;
    EXPECT_EQ(encode_subset_summary(taken), encode_subset_summary(own)) << what;
  });
}

// Without carried keys (a metric cheaper to cost than to remember: the quadric), the sample
// leaves the keys alone.
TEST(RoundShares, WithoutCarriedKeysTheKeysStayEmpty) {
  testing::RoundZero round("stratocaster-9k.ply", SimplifyOptions{}, 2);
  for (SubsetJob& job : round.jobs) {
    const SubsetSample sample =
        sample_subset(job, free_vertices(job.mesh, job.owned), false, job.keys);
    EXPECT_FALSE(sample.costs.empty());
    EXPECT_TRUE(job.keys.empty());
  }
}

// The master costs a cheap metric's sample on the whole mesh (sample_on_master): the same
// edges, and the same costs bit for bit, as the job's own module costs on the job's mesh, for
// either metric (the master's state is the job's).
TEST(RoundShares, TheMasterCostsTheSampleAsTheJobsModuleDoes) {
  for (const char* metric : {"quadric", "energy"})
    for (const char* name : {"stratocaster-9k.ply", "pymeshlab-colored-airplane-11k.ply"}) {
      SimplifyOptions options;
      options.metric = metric;
      testing::RoundZero round(name, options, 3);
      for (SubsetJob& job : round.jobs) {
        const std::string what =
            std::string(metric) + " " + name + " subset " + std::to_string(job.subset);
        const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
        std::vector<EdgeKey> no_keys;
        const SubsetSample own = sample_subset(job, free, false, no_keys);
        Simplifier master_costs(round.whole, *round.master, {});
        const SubsetSample master =
            sample_on_master(job, sampled_edges(job, free), master_costs, *round.master);
        EXPECT_EQ(master.inner_edges, own.inner_edges) << what;
        ASSERT_FALSE(own.costs.empty()) << what;
        ASSERT_EQ(master.costs.size(), own.costs.size()) << what;
        for (size_t i = 0; i < own.costs.size(); ++i)
          ASSERT_EQ(master.costs[i], own.costs[i]) << what << " edge " << i;
        EXPECT_EQ(master.costings, master.costs.size()) << what;
      }
    }
}

// An edge between copies of two groups, which the module alone cannot place, is sampled at the
// cost of the seam collapse the job would make of it (Simplifier::cost_now), by the job's
// module and by the master alike: a subset of a double-sided sheet, whose copies simplify
// only by seam collapses, samples as cheap as it is, and is asked for its share of the faces.
TEST(RoundShares, AnEdgeBetweenCopiesCostsItsSeamCollapse) {
  for (const char* metric : {"quadric", "energy"}) {
    SimplifyOptions options;
    options.metric = metric;
    testing::RoundZero round(repair_mesh(testing::double_sided_sheet_beside_a_sphere(24)), options,
                             2);
    ASSERT_FALSE(round.groups.empty());
    Simplifier master_costs(round.whole, *round.master, {});
    master_costs.join_copies(&round.groups);
    uint64_t seams = 0, costed = 0;
    for (SubsetJob& job : round.jobs) {
      const std::string what = std::string(metric) + " subset " + std::to_string(job.subset);
      const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
      std::vector<EdgeKey> keys;
      const SubsetSample own = sample_subset(job, free, true, keys);
      const SampledEdges edges = sampled_edges(job, free);
      const SubsetSample master = sample_on_master(job, edges, master_costs, *round.master);
      ASSERT_EQ(own.costs.size(), edges.edges.size()) << what;
      ASSERT_EQ(master.costs, own.costs) << what;
      const CopyGroups groups = copy_groups_of(job.copy_group);
      for (size_t i = 0; i < edges.edges.size(); ++i) {
        const auto [a, b] = edges.edges[i];
        if (!groups.is_copy(a) || !groups.is_copy(b)) continue;
        ++seams;
        costed += std::isfinite(own.costs[i]) ? 1 : 0;
        // Not the module's key: the job's memo must not answer the edge with it.
        const auto key = std::find_if(keys.begin(), keys.end(),
                                      [&](const EdgeKey& k) { return k.a == a && k.b == b; });
        ASSERT_NE(key, keys.end()) << what;
        EXPECT_TRUE(std::isnan(key->cost)) << what;
      }
    }
    std::printf("%s: %llu of %llu sampled edges between copies costed\n", metric,
                (unsigned long long)costed, (unsigned long long)seams);
    EXPECT_GT(seams, 100u) << metric;
    EXPECT_GE(costed, seams * 95 / 100) << metric;
  }
}

// Two subsets: 900 inner edges sampled by 9 costs (1 ... 9, each standing for 100 edges) and
// 100 edges by 10 costs (10 ... 19, each for 10). A round removing 400 faces takes about 200
// collapses of 1000 edges: the water level is at the 20% quantile of the edges, 3 (counting
// samples alike, it would be the 4th of 19 costs, 4), and the ceiling is the larger of twice
// that and the 40% quantile, 5: 6. The cheap edges, the 50% quantile and below (6), are 6 of
// the first subset's 9 and none of the second's.
TEST(RoundShares, EachSampledEdgeStandsForItsSubsetsEdges) {
  std::vector<SubsetSample> samples(2);
  samples[0].inner_edges = 900;
  for (int c = 1; c <= 9; ++c) samples[0].costs.push_back(c);
  samples[1].inner_edges = 100;
  for (int c = 10; c <= 19; ++c) samples[1].costs.push_back(c);
  const RoundCosts costs = round_costs_of(samples, 400, 2.0);
  EXPECT_EQ(costs.ceiling, 6.0);
  ASSERT_EQ(costs.cheap_fraction.size(), 2u);
  EXPECT_DOUBLE_EQ(costs.cheap_fraction[0], 6.0 / 9.0);
  EXPECT_EQ(costs.cheap_fraction[1], 0.0);
  // Without a factor, no ceiling; the shares are the same.
  const RoundCosts no_ceiling = round_costs_of(samples, 400, 0.0);
  EXPECT_EQ(no_ceiling.ceiling, std::numeric_limits<double>::infinity());
  EXPECT_EQ(no_ceiling.cheap_fraction, costs.cheap_fraction);
  // Edges the module cannot place (infinite) rank last: in place of the dearest three, they
  // change nothing below them.
  for (int k = 6; k < 9; ++k) samples[0].costs[k] = std::numeric_limits<double>::infinity();
  const RoundCosts unplaced = round_costs_of(samples, 400, 2.0);
  EXPECT_EQ(unplaced.ceiling, 6.0);
  EXPECT_EQ(unplaced.cheap_fraction, costs.cheap_fraction);
  // No sample at all: no ceiling, no shares.
  EXPECT_TRUE(round_costs_of({SubsetSample{}, SubsetSample{}}, 400, 2.0).cheap_fraction.empty());
}

}  // namespace
}  // namespace parapm
