// Quadrics a worker holds between the rounds of one build. A quadric job's free vertices end
// their round with quadrics both sides can compute alike, bit for bit, from the job and its
// records: the worker keeps them, and the coordinator, knowing what it keeps, leaves out of a
// later job of that worker the quadrics it holds unchanged (88 bytes each), sending their ids
// and one fingerprint of them instead. Plain data and arithmetic: the service layer moves it.
#pragma once

#include <cstdint>
#include <vector>

#include "parallel/subset_job.h"
#include "simplify/module_state.h"
#include "simplify/quadric.h"

namespace parapm {

// A 64-bit fingerprint of a quadric's bits, and of a list of them in order: equal quadrics
// give equal fingerprints; unequal ones differ but by a 2^-64 chance (not a cryptographic
// hash: it guards against a worker's mistaken cache, not against a forger).
uint64_t quadric_fingerprint(const Quadric& q);
uint64_t quadrics_fingerprint(const std::vector<Quadric>& quadrics);

// The quadrics `job`'s free vertices (subset_rule.h) start with, in global ids (increasing):
// its state's (a quadric job's state lists exactly those), or, for a job without one (round
// 0), what the job's own initialisation gives them. Empty for a job of another metric.
QuadricState initial_free_quadrics(const SubsetJob& job);

// Follows a job's `records` (global ids, in order) through `quadrics` (initial_free_quadrics):
// Q_vs += Q_vt, as the job's module and the master do. Error(kInvalidInput) when a record
// names a vertex the state does not list.
void follow_records(QuadricState& quadrics, const std::vector<CollapseRecord>& records);

// Moves out of `state` (a job's quadric state, local ids) the quadrics at the indices `held`
// flags (one flag per entry) and returns their vertices' local ids, increasing, and their
// fingerprint (quadrics_fingerprint of them in that order).
struct HeldOut {
  std::vector<VertexId> vertices;
  uint64_t fingerprint = 0;
};
HeldOut take_out_held(QuadricState& state, const std::vector<uint8_t>& held);

// Puts `quadrics` back into `state` at `vertices` (local ids, increasing, none of them already
// in `state`), keeping its ids increasing. Error(kInvalidInput) when the lists disagree in
// size, are not increasing, or name a vertex `state` lists.
void put_back_held(QuadricState& state, const std::vector<VertexId>& vertices,
                   const std::vector<Quadric>& quadrics);

}  // namespace parapm
