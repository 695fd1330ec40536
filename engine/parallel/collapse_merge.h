// Merging the subsets' collapse records into one sequence, and replaying it on the whole
// mesh (METHOD.md section 4, weakness 4: the 1999 merge interleaved the workers' records
// round-robin, so a prefix of the PM was not the cheapest part of the work).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "simplify/collapse_mesh.h"
#include "simplify/modules.h"
#include "simplify/simplifier.h"

namespace parapm {

// k-way merge by cost: repeatedly takes, among the first untaken record of each list, the one
// of least cost (ties to the lower list index). Each list's own order is kept, which is all
// the subset rule needs for the sequence to replay (subset_rule.h); a list's costs need not
// be sorted (a subset's cost sequence is only roughly increasing). O(n log k).
std::vector<CollapseRecord> merge_by_cost(std::vector<std::vector<CollapseRecord>> lists);
// The same merge as the records' addresses, appended to `out`: no record moves (the PM's
// assembly reads them where their lists hold them).
void append_merge_order(const std::vector<std::vector<CollapseRecord>>& lists,
                        std::vector<const CollapseRecord*>& out);

struct ReplayReport {
  uint64_t collapses = 0;
  double slowest_seconds = 0;  // replay_subsets: the longest subset's replay
  // Records whose wedge changes differ from those `priority` computed on the whole mesh (the
  // module's state then differs from the subset's: extra random points drawn per subset).
  uint64_t attribute_mismatches = 0;
};

// Performs `records` on `mesh` in order, checking that each is an edge of the present mesh
// with the faces, apexes, corner wedges and positions the record names (else
// Error(kInvalidInput): the subset rule was broken, or the records did not come from a job of
// this mesh); a record to complete (CollapseRecord::to_complete) gets its apexes, corner
// wedges and positions from the mesh instead, so that no worker can make a PM whose splits
// do not restore the input. When `priority` is given
// (initialised on `mesh` before the first record), it is told of every collapse, so that its state
// follows the mesh (the final pass continues with it); the records' own wedge changes and errors
// are kept.
ReplayReport replay_collapses(CollapseMesh& mesh, std::vector<CollapseRecord>& records,
                              PriorityModule* priority);

// Performs each subset's records (lists[s], in its order) on `mesh`, the subsets side by side
// on up to `threads` threads (0: the hardware's), with `beside`, if given, as one more task
// beside them. By the subset rule (subset_rule.h) a subset's collapses read and change only
// its own vertices' face lists, its own faces and the mixed faces no collapse changes: the
// mesh ends exactly as replay_collapses of any merge of the lists (merge_by_cost) leaves it,
// whatever the threads. Each record is checked as replay_collapses checks it, after the rule
// itself on the present mesh (vs, vt and all their neighbours owned by subset s in
// `vertex_subset`, one entry per vertex of the mesh) and before anything of it is changed: a
// job that broke the rule is refused (Error(kInvalidInput)), not raced. The mesh is left
// partly replayed then.
ReplayReport replay_subsets(CollapseMesh& mesh, std::vector<std::vector<CollapseRecord>>& lists,
                            const std::vector<uint32_t>& vertex_subset, unsigned threads,
                            const std::function<void()>& beside = {});

}  // namespace parapm
