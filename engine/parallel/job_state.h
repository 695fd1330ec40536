// The metric state that travels with a subset job (simplify/module_state.h): the master's
// module exports each job's part in the job's local ids, the job's module imports it instead
// of initialising (so that a job of any round sees the sequential build's sample points and
// quadrics), and the job returns the state of what it owns, which the master imports instead
// of re-running collapsed() on every merged record. The quadric's travels one way only, and
// not in round 0 (job_state_needed, returns_state).
#pragma once

#include <memory>

#include "parallel/subset_job.h"
#include "simplify/module_state.h"
#include "simplify/modules.h"
#include "simplify/simplifier.h"

namespace parapm {

// Whether a job of `master`'s metric needs the master's state (when it does not, the job
// initialises its own module, to the same state): not for the quadric's jobs of round 0, on
// the input mesh, whose owned vertices' quadrics are sums over their whole fans (the job's
// halo, subset_job.h) in the master's order (local ids follow global ones). 56-88 bytes per
// vertex a job need not carry.
bool job_state_needed(const PriorityModule& master, uint32_t round);

// Whether a job of `module`'s metric returns its state. The quadric's does not: its quadrics
// change only by collapsed() (Q_vs += Q_vt), which the master follows from the job's records
// (import_result_states) exactly, at the cost of a copy.
bool returns_state(const PriorityModule& module);
// The metric of the state `job`'s result carries: its state's, or none (empty) for a job without
// one or of a metric that returns none. (What a worker's reply must hold.)
std::string returned_state_metric(const SubsetJob& job);

// The master's state of the job's faces, vertices and wedges, in the job's local ids.
// `master` is the module make_priority_module made for the job's metric, initialised on the
// whole mesh. Const: jobs may be exported concurrently. `loops` (null: one thread): the energy's
// points written in its chunks (the same state).
MetricState export_job_state(const PriorityModule& master, const SubsetJob& job,
                             ChunkedLoops* loops = nullptr);

// Builds the job's module state from job.state (instead of initialize()). Throws
// Error(kInvalidInput) when the state does not fit the module or the job's mesh. `loops` (null:
// one thread): the energy's points listed in its chunks (the same module).
void import_job_state(PriorityModule& module, const CollapseMesh& mesh, const SubsetJob& job,
                      ChunkedLoops* loops = nullptr);

// Whether a job's module may read its state straight from `master`, in this process (energy
// without attributes: EnergyPriority::import_from), instead of through export_job_state and
// import_job_state; import_from_master does, to the same module, without the state's copy.
bool imports_from_master(const PriorityModule& master, const SubsetJob& job);
void import_from_master(PriorityModule& module, const CollapseMesh& mesh, const SubsetJob& job,
                        const PriorityModule& master, ChunkedLoops* loops = nullptr);

// The job's module state at its end, in global ids: what its collapses `records` (in local
// ids) changed, the rest being as the master has it (the energy's faces around them, their
// corners and wedges); for a metric that returns none (returns_state), an empty state.
// `loops` (null: one thread): the energy's points written in its chunks (the same state).
MetricState export_result_state(const PriorityModule& module, const CollapseMesh& mesh,
                                const SubsetJob& job, const std::vector<CollapseRecord>& records,
                                ChunkedLoops* loops = nullptr);

// The master takes a job's returned state, or follows its `records` (global ids) where the
// metric returns none. The jobs of a round own disjoint faces, vertices and wedges, and mixed
// faces never change (subset_rule.h), so the order of imports is free.
void import_result_state(PriorityModule& master, const MetricState& state,
                         const std::vector<CollapseRecord>& records);

// The states of a round's jobs (states[k]: subset k's job's, metric `master`'s) into the
// master, side by side on `threads` threads (0: the hardware's): every state is checked first,
// each only against its own subset (`vertex_subset`: per vertex its subset; `face_subset`: per
// face the subset owning its three corners, kNoId for none), and refused with
// Error(kInvalidInput) before the master changes (a worker's reply is untrusted: a state
// naming another subset's face would have two threads write it); then all are taken, side by
// side (their faces, vertices and points are disjoint; a curve sample on an edge between two
// subsets is written by the subset of its first end), then the wedges, one state after the
// other. The master's result is import_result_state's of each, in any order. `records`
// (records[k]: the records of state k's job, in global ids): each state must also cover what
// they changed (check_state_covers); a metric that returns no state (returns_state) follows
// them instead, each list checked first as a state is, and the states must be empty. May be
// left out for a metric that returns states. With fewer states than `cores` (the build's p; 0:
// as many as states), each energy state's check and take run in cores / states chunks.
struct ImportTimes {
  double seconds = 0;                // wall
  double critical_seconds = 0;       // with a core per state: the steps' slowest ones, in turn
  double slowest_check_seconds = 0;  // CPU
  double slowest_apply_seconds = 0;  // CPU
};
ImportTimes import_result_states(
    PriorityModule& master, const std::vector<const MetricState*>& states,
    const std::vector<uint32_t>& vertex_subset, const std::vector<uint32_t>& face_subset,
    unsigned threads, const std::vector<const std::vector<CollapseRecord>*>& records = {},
    unsigned cores = 0);

// Throws Error(kInvalidInput) unless `state`, a job's returned state, covers what its job's
// `records` (global ids) changed: the two ends of every collapse and, for the energy, the two
// faces it removed, its lists in increasing order as exports write them. The checks of a
// state's entries (check_global) cannot see what it leaves out: a reply without a removed face
// would leave that face's points in the master, held twice; without vs, a stale quadric.
void check_state_covers(const MetricState& state, const std::vector<CollapseRecord>& records);

// Forwards to `inner` except initialize(), which does nothing: for a module whose state was
// imported or carried over (the master's, continued by the final pass).
std::unique_ptr<PriorityModule> without_initialize(PriorityModule& inner);

}  // namespace parapm
