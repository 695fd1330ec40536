// State a worker holds between the rounds of one build, so that later jobs of that worker
// need not carry it: the coordinator, knowing what the worker keeps, leaves it out of the job
// (job_codec.h: the state's items at the held indices travel as their ids alone), sending the
// indices and one fingerprint of what it left out instead. Two kinds, by the metric:
//  - the quadric's: a quadric job's free vertices end their round with quadrics both sides can
//    compute alike, bit for bit, from the job and its records (88 bytes each);
//  - the energy's: its sample points' positions and attribute values, which never change (24
//    bytes each for a drawn point, 12 for a vertex's, plus 4 per attribute float), and their
//    distances (and attribute residuals) as the worker's job left them.
// Plain data and arithmetic: the service layer moves it.
#pragma once

#include <cstdint>
#include <utility>
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

// The quadric state's entries at `held` (indices in its order, increasing) get `quadrics` (in
// `held`'s order). Error(kInvalidInput) when an index is past the entries or the sizes disagree.
void put_back_held_quadrics(QuadricState& state, const std::vector<uint32_t>& held,
                            const std::vector<Quadric>& quadrics);

// What a job's state holds that its worker may hold already, as (id, fingerprint) pairs in
// the state's order: a quadric job's (global vertex, quadric_fingerprint) per state entry; an
// energy job's (point id, point_fingerprint) per point. Empty for a job without a state.
// Error(kInvalidInput) for a quadric state naming a vertex out of the job.
std::vector<std::pair<uint32_t, uint64_t>> holdable_items(const SubsetJob& job);

// What a worker holds of a point besides its attribute values.
struct HeldPoint {
  Vec3 position{};
  double distance_sq = 0;
  double residual = 0;
};
// The fingerprint of a point (its position's, distance's, residual's and k attribute values'
// bits); of point i of an energy state with positions; of a list of fingerprints in order.
uint64_t point_fingerprint(const HeldPoint& point, const float* values, size_t k);
uint64_t point_fingerprint(const EnergyState& state, size_t i);
uint64_t fingerprints_fingerprint(const std::vector<uint64_t>& fingerprints);

// An energy job's items as its worker holds them after the job (holdable_items of its state
// with the distances and residuals of the points `returned`, its result's state, instead).
std::vector<std::pair<uint32_t, uint64_t>> held_items_after(const SubsetJob& job,
                                                            const EnergyState& returned);

// The energy state's points at `held` (indices in its point order, increasing) get `points`
// and `values` (k floats each, in `held`'s order). Error(kInvalidInput) when an index is past
// the points or the sizes disagree.
void put_back_held_points(EnergyState& state, const std::vector<uint32_t>& held,
                          const std::vector<HeldPoint>& points, const std::vector<float>& values);

}  // namespace parapm
