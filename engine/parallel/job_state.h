// The metric state that travels with a subset job (simplify/module_state.h): the master's
// module exports each job's part in the job's local ids, the job's module imports it instead
// of initialising (so that a job of any round sees the sequential build's sample points and
// quadrics), and the job returns the state of what it owns, which the master imports instead
// of re-running collapsed() on every merged record.
#pragma once

#include <memory>

#include "parallel/subset_job.h"
#include "simplify/module_state.h"
#include "simplify/modules.h"
#include "simplify/simplifier.h"

namespace parapm {

// The master's state of the job's faces, vertices and wedges, in the job's local ids.
// `master` is the module make_priority_module made for the job's metric, initialised on the
// whole mesh. Const: jobs may be exported concurrently.
MetricState export_job_state(const PriorityModule& master, const SubsetJob& job);

// Builds the job's module state from job.state (instead of initialize()). Throws
// Error(kInvalidInput) when the state does not fit the module or the job's mesh.
void import_job_state(PriorityModule& module, const CollapseMesh& mesh, const SubsetJob& job);

// The job's module state at its end, in global ids: what its collapses `records` (in local
// ids) changed, the rest being as the master has it (the quadrics of their vertices; the
// energy's faces around them, their corners and wedges).
MetricState export_result_state(const PriorityModule& module, const CollapseMesh& mesh,
                                const SubsetJob& job, const std::vector<CollapseRecord>& records);

// The master takes a job's returned state. The jobs of a round own disjoint faces, vertices
// and wedges, and mixed faces never change (subset_rule.h), so the order of imports is free.
void import_result_state(PriorityModule& master, const MetricState& state);

// Forwards to `inner` except initialize(), which does nothing: for a module whose state was
// imported or carried over (the master's, continued by the final pass).
std::unique_ptr<PriorityModule> without_initialize(PriorityModule& inner);

}  // namespace parapm
