// A subset job: everything one worker needs to simplify its subset of a mesh, and nothing
// more (METHOD.md section 4, weakness 1: the 1999 workers each loaded the whole mesh). Plain
// data, so that the service layer can serialise it; the same job runs in a thread of the
// in-process parallel build (parallel_build.h) and, later, in a worker daemon.
//
// Contents: the live faces that touch a vertex the subset owns (a vertex belongs to exactly
// one subset, partition.h), in local ids. Those faces are the subset's own faces plus a
// one-ring halo of read-only faces: every face around an owned vertex is present, so that
// the fan, boundary status, quadric, sharp edges and sample points of every owned vertex are
// those of the whole mesh (subset_rule.h says why that is all a legal collapse reads).
// Local ids follow the global order (vertex, face and wedge i < j locally iff globally), so
// that the simplifier's ties, broken by ids, fall as on the whole mesh.
//
// Memory: proportional to the subset plus its halo (about 24 B + 9 B per vertex, 12 B +
// 4 B per face, plus attributes), never to the whole mesh.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "parallel/edge_keys.h"
#include "simplify/collapse_mesh.h"
#include "simplify/copy_groups.h"
#include "simplify/module_state.h"
#include "simplify/simplifier.h"
#include "simplify/simplify.h"
#include "util/chunked_loops.h"

namespace parapm {

// The options of a subset's simplification (a subset of SimplifyOptions, plus what only the
// whole mesh knows).
struct SubsetOptions {
  std::string metric = "quadric";  // "quadric" or "energy"
  double samples_per_face = 1;
  double crease_angle_degrees = 180;
  double attribute_weight = 0.01;
  EnergyTuning energy;
  uint64_t seed = 1;  // already mixed with the round and subset index by the extraction
  // The whole mesh's bounding-box diagonal: energy costs are measured against it, so that
  // the costs of different subsets compare (quadric costs are absolute already).
  double reference_diagonal = 0;
  // Stop once the job's mesh (halo included) has at most this many live faces; 0: go as far
  // as the subset rule allows.
  uint64_t target_faces = 0;
  // Collapses costing more are left to later rounds or the final pass; 0: no limit. The
  // parallel build sets it below the energy's topology penalty, so that a job that must
  // remove its share does not change the curves' topology where a sequential run, cheapest
  // first, would not have come to that yet.
  double max_cost = 0;
  // Edges around a collapse costed when they come to the top of the queue, not at once
  // (SimplifierLimits::defer_above_faces): set for rounds above the sequential build's line.
  bool defer_recosting = false;
  // The quadric placed at its free optimum throughout (QuadricOptions::
  // free_placement_above_faces 0), not constrained: set for rounds that start above the
  // sequential build's line (free_placement_line), as the master places then.
  bool free_placement = false;
};

// The options a job's metric is made from, named alike in SimplifyOptions and SubsetOptions:
// one list, for both directions (subset_options_of, simplify_options_of).
template <typename To, typename From>
void copy_metric_options(const From& from, To& to) {
  to.metric = from.metric;
  to.samples_per_face = from.samples_per_face;
  to.crease_angle_degrees = from.crease_angle_degrees;
  to.attribute_weight = from.attribute_weight;
  to.energy = from.energy;
  to.seed = from.seed;
}

// The subset options a simplification with `options` gives its jobs, measured against the
// whole `mesh` (its bounding-box diagonal); target_faces and max_cost are left to the caller.
SubsetOptions subset_options_of(const SimplifyOptions& options, const Mesh& mesh);

struct SubsetJob {
  uint32_t round = 0;                   // 0-based
  uint32_t subset = 0;                  // index in the partition
  Mesh mesh;                            // local ids; positions_are_float is the whole mesh's
  std::vector<VertexId> global_vertex;  // local vertex -> id in the whole mesh
  std::vector<FaceId> global_face;      // local face -> id in the whole mesh
  std::vector<WedgeId> global_wedge;    // local wedge -> id (empty without attributes)
  std::vector<uint8_t> owned;           // per local vertex: 1 if the subset owns it, 0: halo
  std::vector<uint8_t> locked;          // per local vertex: a repair copy (only seams move it)
  // Per local vertex: its group of copies (copy_groups.h), named by the group's first vertex in
  // the job, when every live copy of the group is in the job (the job makes seam collapses of
  // those); kNoId otherwise (a copy whose group continues outside the job stays). Empty: none.
  std::vector<uint32_t> copy_group;
  uint64_t owned_faces = 0;  // faces whose three vertices are owned
  SubsetOptions options;
  // The metric's state over the job, in local ids (job_state.h): the master's sample points,
  // curves, wedge classes or quadrics. Empty: the job initialises its metric on its own mesh
  // (its own random points, seeded per round and subset).
  MetricState state;
  // Queue keys still current on the master (edge_keys.h), in local ids, a < b, sorted; only
  // of edges with two free ends (subset_rule.h), the only ones the job costs.
  std::vector<EdgeKey> keys;
  // Edges with two free ends that a job of an earlier round left deferred (its
  // Simplifier::deferred_edges(), still so on the master), in local ids, sorted, none of them
  // among `keys`: the job queues them deferred while it defers, as the sequential build holds
  // them, instead of costing them at once (SimplifierLimits::first_deferred).
  std::vector<DeferredEdge> deferred;
};

// Builds the job of every subset of `vertex_subset` (per global vertex its subset in
// [0, subsets), ignored for dead vertices) over the live part of `mesh`. `wedge_values` are
// the current values of the whole mesh's wedges (layout.floats_per_wedge() each; empty
// without attributes); `locked` per global vertex (may be empty); `groups` the whole mesh's
// copy groups (null: none). `options` is copied into every job (target_faces is left for the
// caller). O(live faces + sum of the jobs' sizes).
std::vector<SubsetJob> extract_subsets(const CollapseMesh& mesh, const AttributeLayout& layout,
                                       const std::vector<float>& wedge_values,
                                       bool positions_are_float, const std::vector<uint8_t>& locked,
                                       const std::vector<uint32_t>& vertex_subset, uint32_t subsets,
                                       uint32_t round, const SubsetOptions& options,
                                       const CopyGroups* groups = nullptr);

// The two steps of extract_subsets, for a caller that builds the jobs concurrently: the live
// vertices of each subset, in id order (checked against the mesh, O(vertices); in `loops`'
// chunks, the same lists), then one subset's job from its list (const reads of `mesh` only:
// jobs may be built in parallel).
std::vector<std::vector<VertexId>> owned_vertices(const CollapseMesh& mesh,
                                                  const std::vector<uint32_t>& vertex_subset,
                                                  uint32_t subsets);
std::vector<std::vector<VertexId>> owned_vertices(const CollapseMesh& mesh,
                                                  const std::vector<uint32_t>& vertex_subset,
                                                  uint32_t subsets, ChunkedLoops& loops);
SubsetJob extract_subset(const CollapseMesh& mesh, const AttributeLayout& layout,
                         const std::vector<float>& wedge_values, bool positions_are_float,
                         const std::vector<uint8_t>& locked,
                         const std::vector<uint32_t>& vertex_subset,
                         const std::vector<VertexId>& owned, uint32_t subset, uint32_t round,
                         const SubsetOptions& options, const CopyGroups* groups = nullptr);

// A record of the job's simplification (its ids local) in the whole mesh's ids, in place.
void to_global_ids(CollapseRecord& record, const SubsetJob& job);

// Checks what a job can check on its own: sizes agree, local ids in range, global ids
// strictly increasing, every face touches an owned vertex. Throws Error(kInvalidInput)
// naming the first violation. A worker calls it on a job that came over the network.
void validate_subset_job(const SubsetJob& job);

}  // namespace parapm
