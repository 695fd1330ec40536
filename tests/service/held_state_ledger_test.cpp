// The coordinator's ledger of held state (server/held_state_ledger.h): a job is planned for
// the worker holding most of its items unchanged (here quadrics), only those it holds with the
// same value are left out, and no worker is planned more than its share of the round's jobs.
#include <gtest/gtest.h>

#include "held_state_ledger.h"
#include "parallel/held_state.h"

namespace parapm::service {
namespace {

Quadric quadric_of(VertexId v, double weight = 1) {
  return Quadric::from_plane({0, 0, 1}, -double(v), weight);
}

// A quadric job's items: the quadrics of global vertices `vertices`, as its state holds them.
HeldStateLedger::Items job_of(const std::vector<VertexId>& vertices) {
  HeldStateLedger::Items items;
  for (VertexId v : vertices) items.emplace_back(v, quadric_fingerprint(quadric_of(v)));
  return items;
}

std::vector<std::pair<uint32_t, uint64_t>> kept(const std::vector<VertexId>& vertices) {
  std::vector<std::pair<uint32_t, uint64_t>> out;
  for (VertexId v : vertices) out.emplace_back(v, quadric_fingerprint(quadric_of(v)));
  return out;
}

TEST(HeldStateLedger, AJobGoesToTheWorkerHoldingMostOfItsQuadricsUnchanged) {
  HeldStateLedger ledger;
  ledger.record("a", kept({0, 1, 2}));
  ledger.record("b", kept({3, 4, 5, 6}));
  ledger.record("b", {{7, quadric_fingerprint(quadric_of(7, 2))}});  // another value than now
  std::vector<HeldStateLedger::Items> jobs = {job_of({1, 2, 3, 4, 5, 6, 7, 9})};
  const auto plans = ledger.plan_round(jobs, {{"a", 1}, {"b", 1}});
  ASSERT_EQ(plans.size(), 1u);
  EXPECT_EQ(plans[0].worker, "b");
  EXPECT_EQ(plans[0].count, 4u);
  EXPECT_EQ(plans[0].held, (std::vector<uint8_t>{0, 0, 1, 1, 1, 1, 0, 0}));
  // b not live (or distrusted): a, for the two it holds.
  const auto without_b = ledger.plan_round(jobs, {{"a", 1}});
  EXPECT_EQ(without_b[0].worker, "a");
  EXPECT_EQ(without_b[0].held, (std::vector<uint8_t>{1, 1, 0, 0, 0, 0, 0, 0}));
  // A vertex's latest job decides who holds it.
  ledger.record("a", kept({3, 4, 5, 6}));
  EXPECT_EQ(ledger.plan_round(jobs, {{"a", 1}, {"b", 1}})[0].worker, "a");
  // Nobody holds anything of a fresh job.
  EXPECT_TRUE(ledger.plan_round({job_of({20, 21})}, {{"a", 1}})[0].worker.empty());
}

TEST(HeldStateLedger, NoWorkerIsPlannedMoreThanItsShare) {
  HeldStateLedger ledger;
  ledger.record("a", kept({0, 1, 2, 3, 4, 5, 6, 7, 8, 9}));
  ledger.record("b", kept({10}));
  // All four jobs hold most with a; a and b have a slot each: two each at most, the jobs
  // holding the most with a placed there first.
  std::vector<HeldStateLedger::Items> jobs = {job_of({0, 10}), job_of({1, 2, 3, 11}),
                                              job_of({4, 5, 6, 7}), job_of({8, 9, 12})};
  const auto plans = ledger.plan_round(jobs, {{"a", 1}, {"b", 1}});
  EXPECT_EQ(plans[1].worker, "a");
  EXPECT_EQ(plans[2].worker, "a");
  EXPECT_EQ(plans[0].worker, "b");  // a full, b holds one of job 0's
  EXPECT_EQ(plans[0].held, (std::vector<uint8_t>{0, 1}));
  EXPECT_TRUE(plans[3].worker.empty());  // a full, b holds none of job 3's
  // With three slots to b's one, a takes three of the four.
  const auto weighted = ledger.plan_round(jobs, {{"a", 3}, {"b", 1}});
  EXPECT_EQ(weighted[3].worker, "a");
  EXPECT_EQ(weighted[0].worker, "b");
}

}  // namespace
}  // namespace parapm::service
