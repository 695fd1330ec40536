// Shared by the parallel tests: a repaired real mesh, and a PM serialised to bytes.
#pragma once

#include <algorithm>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "parallel/edge_keys.h"
#include "parallel/job_state.h"
#include "parallel/parallel_build.h"
#include "parallel/subset_job.h"
#include "parallel/subset_rule.h"
#include "partition/partition.h"
#include "pm/pm_file.h"
#include "simplify/modules.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm::testing {

inline RepairedMesh repaired_test_mesh(const std::string& name) {
  return repair_mesh(read_mesh(test_data(name)));
}

// The sequential build at p = 1, else the parallel build on p subsets, with rounds down to
// subsets of `min_subset_faces` (small drawn meshes get rounds too).
inline ProgressiveMesh build_with_subsets(const RepairedMesh& repaired,
                                          const SimplifyOptions& options, uint32_t p,
                                          uint64_t min_subset_faces) {
  if (p == 1) return build_progressive_mesh(repaired, options);
  ParallelOptions parallel;
  parallel.subsets = p;
  parallel.min_subset_faces = min_subset_faces;
  return build_progressive_mesh_parallel(repaired, options, parallel);
}

// Round 0 of a p-subset build of a test mesh, as the parallel build starts it: the whole mesh,
// the master's module initialised on it, and every subset's job with the master's state (no
// target, no keys: the test sets them).
struct RoundZero {
  RoundZero(const std::string& name, const SimplifyOptions& options, uint32_t p)
      : RoundZero(repaired_test_mesh(name), options, p) {}
  RoundZero(RepairedMesh input, const SimplifyOptions& options, uint32_t p)
      : repaired(std::move(input)),
        locked(locked_vertices(repaired)),
        groups(copy_groups(repaired)),
        whole(repaired.mesh),
        master(make_priority_module(options, repaired.mesh, locked)) {
    const Mesh& mesh = repaired.mesh;
    master->initialize(whole);
    Partition partition = partition_mesh(mesh, p);
    // As the build's partitions do, all the copies of a group in one subset.
    for (VertexId v = 0; v < mesh.vertex_count(); ++v)
      if (groups.is_copy(v))
        partition.vertex_subset[v] = partition.vertex_subset[groups.of(groups.group[v])[0]];
    jobs =
        extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float, locked,
                        partition.vertex_subset, p, 0, subset_options_of(options, mesh), &groups);
    for (SubsetJob& job : jobs) {
      job.state = export_job_state(*master, job);
      // The quadric's placement as the master's on the whole mesh (the build's round 0).
      job.options.free_placement = whole.live_faces() > free_placement_line(mesh.face_count());
    }
  }
  RepairedMesh repaired;
  std::vector<uint8_t> locked;
  CopyGroups groups;
  CollapseMesh whole;
  std::unique_ptr<PriorityModule> master;
  std::vector<SubsetJob> jobs;
};

// Fresh queue keys of the job's edges with two free ends, costed by the master's module on the
// whole mesh, in the job's local ids: what the job would cost itself.
inline std::vector<EdgeKey> fresh_keys(PriorityModule& master, const CollapseMesh& whole,
                                       const SubsetJob& job) {
  const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
  std::vector<EdgeKey> keys;
  for (const Triangle& t : job.mesh.faces)
    for (int k = 0; k < 3; ++k) {
      const VertexId a = std::min(t[k], t[(k + 1) % 3]), b = std::max(t[k], t[(k + 1) % 3]);
      if (!free[a] || !free[b]) continue;
      CollapseCandidate c;
      const bool placed =
          master.evaluate(whole, job.global_vertex[a], job.global_vertex[b], c, Costing::kQueue);
      keys.push_back({a, b, placed ? c.cost : std::numeric_limits<double>::quiet_NaN()});
    }
  sort_unique_edges(keys);  // an inner edge is listed by both its faces
  return keys;
}

}  // namespace parapm::testing
