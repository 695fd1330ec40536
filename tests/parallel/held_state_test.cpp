// What a worker keeps of a quadric job (held_state.h), its module's quadrics at the end, is
// what the coordinator computes from the job and its records and what the master holds after
// following them: its free vertices' quadrics, bit for bit, with or without a state (round 0's
// jobs initialise their own); a job that leaves out the quadrics or points its worker holds,
// put back, is the job again.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>

#include "parallel/held_state.h"
#include "parallel/job_codec.h"
#include "parallel/simplify_subset.h"
#include "parallel_test_support.h"
#include "simplify/quadric_priority.h"
#include "util/error.h"

namespace parapm {
namespace {

bool same_bits(const Quadric& a, const Quadric& b) {
  return std::memcmp(&a, &b, sizeof(Quadric)) == 0;
}

// For each job, with its state and without (round 0): the quadrics its worker keeps are those
// the master has once it followed every job's records.
TEST(HeldState, AWorkerKeepsWhatTheMasterHoldsAfterTheRound) {
  for (const char* name : {"stratocaster-9k.ply", "cad-cycloidal-43k.ply"}) {
    testing::RoundZero round(name, SimplifyOptions{}, 4);
    auto& master = dynamic_cast<QuadricPriority&>(*round.master);
    std::vector<QuadricState> kept;
    for (SubsetJob& job : round.jobs) {
      job.options.target_faces = job.mesh.face_count() / 3;
      SubsetJob without = job;
      without.state = MetricState{};
      const QuadricState from_state = initial_free_quadrics(job);
      const QuadricState initialised = initial_free_quadrics(without);
      ASSERT_EQ(from_state.vertices, initialised.vertices) << name;
      ASSERT_FALSE(from_state.vertices.empty());
      for (size_t i = 0; i < from_state.vertices.size(); ++i) {
        ASSERT_TRUE(same_bits(from_state.quadrics[i], initialised.quadrics[i]))
            << name << " vertex " << from_state.vertices[i];
        ASSERT_TRUE(same_bits(initialised.quadrics[i], master.quadric(initialised.vertices[i])));
      }
      QuadricState state = initialised;
      QuadricState at_end;
      const SubsetResult result = simplify_subset(without, {}, nullptr, &at_end);
      ASSERT_FALSE(result.records.empty());
      follow_records(state, result.records);
      // The job's own quadrics at its end, as a worker keeps them, are the followed ones.
      ASSERT_EQ(at_end.vertices, state.vertices);
      for (size_t i = 0; i < state.vertices.size(); ++i)
        ASSERT_TRUE(same_bits(at_end.quadrics[i], state.quadrics[i])) << name;
      master.follow_records(result.records);
      kept.push_back(std::move(state));
    }
    size_t compared = 0;
    for (const QuadricState& state : kept)
      for (size_t i = 0; i < state.vertices.size(); ++i, ++compared)
        ASSERT_TRUE(same_bits(state.quadrics[i], master.quadric(state.vertices[i])))
            << name << " vertex " << state.vertices[i];
    EXPECT_GT(compared, round.whole.live_vertices() / 2) << name;
  }
}

TEST(HeldState, ARecordOfAVertexNotFreeIsRefused) {
  testing::RoundZero round("stratocaster-9k.ply", SimplifyOptions{}, 2);
  const SubsetJob& job = round.jobs[0];
  QuadricState state = initial_free_quadrics(job);
  CollapseRecord r;
  r.vs = state.vertices[0];
  r.vt = round.jobs[1].global_vertex[0];  // the other subset's
  ASSERT_FALSE(std::binary_search(state.vertices.begin(), state.vertices.end(), r.vt));
  EXPECT_THROW(follow_records(state, {r}), Error);
}

// A quadric job's quadrics its worker holds travel as their vertices' ids alone, named by their
// indices in the state's order; put back, the state is the job's again.
TEST(HeldState, AQuadricJobLeavesOutTheQuadricsItsWorkerHolds) {
  testing::RoundZero round("stratocaster-9k.ply", SimplifyOptions{}, 2);
  const SubsetJob& job = round.jobs[0];
  const QuadricState& whole = job.state.quadric;
  ASSERT_GT(whole.vertices.size(), 10u);
  const auto items = holdable_items(job);
  ASSERT_EQ(items.size(), whole.vertices.size());
  std::vector<uint32_t> held;
  std::vector<Quadric> quadrics;
  std::vector<uint64_t> fingerprints;
  for (uint32_t i = 0; i < whole.vertices.size(); i += 3) {
    held.push_back(i);
    quadrics.push_back(whole.quadrics[i]);
    fingerprints.push_back(items[i].second);
  }
  EXPECT_EQ(fingerprints_fingerprint(fingerprints), quadrics_fingerprint(quadrics));
  const std::string all = encode_subset_job(job);
  const std::string bytes = encode_subset_job(job, job.state, held);
  EXPECT_EQ(bytes.size(), all.size() - held.size() * 88);
  // The indices travel as the request's list.
  EXPECT_EQ(decode_increasing_ids(encode_increasing_ids(held), whole.vertices.size(), "held"),
            held);

  SubsetJob decoded = decode_subset_job(bytes, held);
  QuadricState& state = decoded.state.quadric;
  ASSERT_EQ(state.vertices, whole.vertices);
  EXPECT_TRUE(same_bits(state.quadrics[held[0]], Quadric{}));
  put_back_held_quadrics(state, held, quadrics);
  for (size_t i = 0; i < whole.quadrics.size(); ++i)
    ASSERT_TRUE(same_bits(state.quadrics[i], whole.quadrics[i])) << i;

  // Indices past the quadrics, or not increasing, and lists that disagree are refused.
  const std::vector<uint32_t> past = {uint32_t(whole.vertices.size())};
  EXPECT_THROW(encode_subset_job(job, job.state, past), Error);
  EXPECT_THROW(decode_subset_job(all, past), Error);
  EXPECT_THROW(decode_subset_job(bytes, {1, 0}), Error);
  EXPECT_THROW(decode_subset_job(bytes, {}), Error);  // the held quadrics' bytes are missing
  EXPECT_THROW(put_back_held_quadrics(state, past, {Quadric{}}), Error);
  EXPECT_THROW(put_back_held_quadrics(state, held, {}), Error);
}

TEST(HeldState, FingerprintsSeeEveryBit) {
  Quadric q = Quadric::from_plane({0, 0, 1}, -1, 2);
  const uint64_t f = quadric_fingerprint(q);
  Quadric signed_zero = q;
  signed_zero.a01 = -0.0;  // equal as a double, not as bits
  EXPECT_NE(quadric_fingerprint(signed_zero), f);
  Quadric nudged = q;
  nudged.weight = std::nextafter(q.weight, 3.0);
  EXPECT_NE(quadric_fingerprint(nudged), f);
  EXPECT_NE(quadrics_fingerprint({q, nudged}), quadrics_fingerprint({nudged, q}));
  EXPECT_NE(quadrics_fingerprint({q}), quadrics_fingerprint({q, q}));
}

TEST(HeldState, AHostileIdListIsRefused) {
  const std::string ids = encode_increasing_ids({3, 7, 9});
  EXPECT_EQ(decode_increasing_ids(ids, 10, "held"), (std::vector<uint32_t>{3, 7, 9}));
  EXPECT_THROW(decode_increasing_ids(ids, 9, "held"), Error);                // 9 out of range
  EXPECT_THROW(decode_increasing_ids(ids + "x", 10, "held"), Error);         // trailing bytes
  EXPECT_THROW(decode_increasing_ids(ids.substr(0, 2), 10, "held"), Error);  // cut short
  EXPECT_THROW(decode_increasing_ids("\xff\xff\xff\xff\x0f", 10, "held"), Error);
  EXPECT_THROW(encode_increasing_ids({3, 3}), Error);
}

// An energy job's points its worker holds travel as their ids alone, named by their indices in
// the state's order; put back, the state is the job's again.
TEST(HeldState, AnEnergyJobLeavesOutThePointsItsWorkerHolds) {
  SimplifyOptions options;
  options.metric = "energy";
  testing::RoundZero round("pymeshlab-colored-airplane-11k.ply", options, 2);
  const SubsetJob& job = round.jobs[0];
  const EnergyState& whole = job.state.energy;
  ASSERT_TRUE(whole.positions);
  ASSERT_GT(whole.points.size(), 100u);
  const size_t k = whole.point_values.size() / whole.points.size();
  ASSERT_GT(k, 0u);  // the airplane's colours
  const auto items = holdable_items(job);
  ASSERT_EQ(items.size(), whole.points.size());
  std::vector<uint32_t> held;
  for (uint32_t i = 0; i < whole.points.size(); i += 2) held.push_back(i);
  const std::string all = encode_subset_job(job);
  const std::string bytes = encode_subset_job(job, job.state, held);
  EXPECT_LT(bytes.size(), all.size() - held.size() * (12 + 8 + 4 * k) / 2);

  SubsetJob decoded = decode_subset_job(bytes, held);
  EnergyState& state = decoded.state.energy;
  ASSERT_EQ(state.points.size(), whole.points.size());
  EXPECT_EQ(state.points[0].position, (Vec3{0, 0, 0}));
  EXPECT_EQ(state.points[0].distance_sq, 0);
  std::vector<HeldPoint> points;
  std::vector<float> values;
  std::vector<uint64_t> fingerprints;
  for (uint32_t i : held) {
    const EnergyState::Point& p = whole.points[i];
    points.push_back({p.position, p.distance_sq, p.residual});
    values.insert(values.end(), whole.point_values.begin() + i * k,
                  whole.point_values.begin() + (i + 1) * k);
    fingerprints.push_back(items[i].second);
    EXPECT_EQ(point_fingerprint(points.back(), values.data() + values.size() - k, k),
              items[i].second);
  }
  put_back_held_points(state, held, points, values);
  for (size_t i = 0; i < whole.points.size(); ++i) {
    ASSERT_EQ(state.points[i].id, whole.points[i].id);
    ASSERT_EQ(state.points[i].position, whole.points[i].position) << i;
    ASSERT_EQ(state.points[i].distance_sq, whole.points[i].distance_sq);
    ASSERT_EQ(state.points[i].residual, whole.points[i].residual);
  }
  EXPECT_EQ(state.point_values, whole.point_values);
  EXPECT_NE(fingerprints_fingerprint(fingerprints),
            fingerprints_fingerprint(
                std::vector<uint64_t>(fingerprints.begin() + 1, fingerprints.end())));

  // Indices past the points, or not increasing, are refused on both sides.
  const std::vector<uint32_t> past = {uint32_t(whole.points.size())};
  EXPECT_THROW(encode_subset_job(job, job.state, past), Error);
  EXPECT_THROW(decode_subset_job(all, past), Error);
  EXPECT_THROW(decode_subset_job(bytes, {1, 0}), Error);
  EXPECT_THROW(put_back_held_points(state, past, {HeldPoint{}}, std::vector<float>(k)), Error);
  EXPECT_THROW(put_back_held_points(state, held, points, {}), Error);

  // After a job, its worker holds the distances its result returns.
  EnergyState returned;
  returned.positions = false;
  EnergyState::Point moved = whole.points[1];
  moved.distance_sq += 1;
  returned.points.push_back(moved);
  const auto after = held_items_after(job, returned);
  ASSERT_EQ(after.size(), items.size());
  EXPECT_EQ(after[0], items[0]);
  EXPECT_NE(after[1], items[1]);
  EXPECT_EQ(after[1].second, point_fingerprint({moved.position, moved.distance_sq, moved.residual},
                                               whole.point_values.data() + k, k));
}

}  // namespace
}  // namespace parapm
