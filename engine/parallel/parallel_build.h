// Parallel construction of a Progressive Mesh (Langis 1999, the "galaxy" method; METHOD.md
// section 4): partition, simplify the subsets in parallel under a rule that keeps their
// collapses independent, merge the records by cost, replay them on the whole mesh, and finish
// the border with a sequential final pass. docs/ARCHITECTURE.md, "Parallel construction",
// says why each step is as it is.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/repair.h"
#include "pm/progressive_mesh.h"
#include "simplify/simplify.h"
#include "util/progress.h"

namespace parapm {

struct ParallelOptions {
  uint32_t subsets = 2;  // p, in [1, 256]
  uint32_t rounds = 1;   // parallel rounds, each on a new partition of the current mesh
  unsigned threads = 0;  // 0: min(p, hardware threads)
  // The parallel rounds take the mesh from F faces down to max(target, handover_ratio x F)
  // faces (geometrically across rounds); the final pass, sequential on the whole mesh,
  // collapses the borders and goes on to the target. Smaller: more parallel work, but the
  // levels near the handover keep the subsets' borders at full resolution (dragon 203k,
  // energy, p = 2: at 0.1 the 10% level's RMS error doubles; at 0.3 every level is within 2%
  // of the sequential build's, docs/ARCHITECTURE.md).
  double handover_ratio = 0.3;
};

struct SubsetTiming {
  uint32_t subset = 0;
  uint64_t faces = 0;  // of its job, halo included
  uint64_t owned_faces = 0;
  uint64_t collapses = 0;
  double wall_seconds = 0;
  double cpu_seconds = 0;
  std::string stop_reason;
};

struct RoundStats {
  uint32_t round = 0;
  uint64_t faces_before = 0;
  uint64_t goal_faces = 0;  // what the round aimed at
  uint64_t faces_after = 0;
  double partition_seconds = 0;
  double extract_seconds = 0;
  double subsets_seconds = 0;  // wall time of the round's jobs
  double merge_seconds = 0;    // k-way merge and replay on the whole mesh
  std::vector<SubsetTiming> subsets;
};

struct ParallelStats {
  uint32_t subsets = 0;
  uint32_t rounds = 0;
  unsigned threads = 0;
  std::vector<RoundStats> round_stats;
  uint64_t final_pass_collapses = 0;
  double final_pass_seconds = 0;
  double pm_build_seconds = 0;
  uint64_t collapses = 0;
  std::string stop_reason;  // of the final pass
  double seconds = 0;       // the whole construction, wall
  double cpu_seconds = 0;   // the subsets' CPU plus the master's (partition, merge, final pass)
};

// Same contract as build_progressive_mesh (simplify.h), whose options it takes; the result is
// a valid, lossless PM reaching the same target. Deterministic: the same input, options, p
// and rounds give the same PM whatever the thread count and timing. Throws
// Error(kInvalidInput) for bad options (p outside [1, 256] or above the vertex count, rounds
// outside [1, 64], handover_ratio outside (0, 1]).
ProgressiveMesh build_progressive_mesh_parallel(const RepairedMesh& repaired,
                                                const SimplifyOptions& options,
                                                const ParallelOptions& parallel,
                                                ParallelStats* stats = nullptr,
                                                const ProgressCallback& progress = {},
                                                const CancelToken* cancel = nullptr);

}  // namespace parapm
