// Binary codec of the parallel build's messages (subset_job.h, simplify_subset.h), so that a
// job can travel to a worker daemon and its results back as opaque bytes: the protocol layer
// never sees a mesh. Exact: every double and float travels as its bits, so that a PM built
// from decoded results is byte-identical to the in-process one.
//
// Layout (little-endian, byte_io.h; "v" is a LEB128 varint, "id+1" a varint of the id plus
// one modulo 2^32 so that kNoId costs one byte, "ids+" strictly increasing ids as the first
// id then each gap minus one, "near" an id as the zigzag varint of its difference from the
// one before it in its list, the first from 0). Every message starts with a 4-byte magic naming its
// kind and a version byte, so that one kind is never decoded as another.
//
//   (The version byte is 10 for every kind; DECISIONS.md, "The job codec's versions", says
//   what each one added.)
//   job     "PPJB" 4 | round v, subset v | V v, F v, W v (counts first: checked before
//           anything is allocated) | options: metric u8 (0 none, 1 quadric, 2 energy),
//           samples_per_face f64, crease_angle f64, attribute_weight f64, star_planes_weight
//           f64, volume_weight f64, spring_scale f64, min_crease_edges v, crease_min_length
//           f64, seed u64, reference_diagonal f64, target_faces v, max_cost f64,
//           defer_recosting u8 (0/1), free_placement u8 (0/1) | mesh flags u8 (1
//           positions_are_float, 2 normals, 4 texcoords, 8 colours, 16 corner wedges, 32
//           positions stored as f32: set when every coordinate is exactly a float) | per
//           vertex: position (3 f32 or 3 f64), owned | locked << 1 | grouped << 2 u8, then
//           (grouped) copy_group v | global_vertex ids+ |
//           per face: 3 corners near | global_face ids+ | per wedge: wedge_vertex near,
//           then all values f32, then (flag 16) per face 3 wedges near | global_wedge ids+ |
//           owned_faces v | state | keys | deferred.
//   state   metric u8, then the metric's part (the other part must be empty):
//           quadric (a job's only: quadric jobs return none): n v, vertices ids+, per vertex
//           but those its worker holds 11 f64 (a00 a01 a02 a11 a12 a22 b0 b1 b2 c w).
//           energy: faces n v + ids+, vertices n v + ids+, k u8 (floats per point and per
//           wedge, 0..9), flags u8 (1: residuals present; 2: positions present, set in a
//           job's state and only there; 4: the points' positions as 3 f32, 8: the curve
//           samples', each set when every one is exactly a float, as an input vertex's is) |
//           per face: its point count v, then its points |
//           curve samples: n v, per sample id near, [position 3 f64], distance_sq f64, u v, w
//           id+1 | per vertex: parked u8 (0/1) [point], sharp count v and neighbours v,
//           listed count v and sample indices v | curve_samples_total v | wedges n v + ids+,
//           n x k f32 values, per wedge (its index - the index of its class's wedge) v. A
//           point: id near, [position 3 f64], distance_sq f64, [residual f64], [k f32 (with
//           positions)]; its face or vertex is the one it is written under (export order);
//           its id is near the point written before it, across faces and vertices. A point
//           its worker holds is its id alone.
//           The items a job's worker holds (quadrics, points) are named by their indices in
//           the state's order (its vertices', its points'), which travel beside the job:
//           encode_subset_job's held_items.
//   keys    n v, then per key (sorted by (a, b), a < b: edge_keys.h) a minus the previous
//           key's a v, b - a - 1 v, cost f64 (NaN: the edge cannot be placed).
//   deferred n v, then per edge (sorted by (a, b), a < b: simplifier.h, DeferredEdge) as a
//           key, with its key f32 in place of the cost.
//   records "PPCR" 4 | n v | k u8 (floats per changed wedge) | per record: flags u8 (1:
//           position as f32), vs v, vt v, fl fr id+1, position (3 f32 or 3 f64), cost f64,
//           error f32, changed n v, n ids v, n x k f32. The apexes, corner wedges and
//           positions before the collapse are left out: the coordinator's replay takes them
//           from its mesh (CollapseRecord::to_complete).
//   summary "PPSS" 4 | round v, subset v | state | keys | deferred | keys_reused v,
//           costings v, faces v, owned_faces v, free_vertices v | collapses rejected stale
//           reevaluated evaluations v, stop_reason (length v <= 4096, bytes) | wall_seconds
//           f64, cpu_seconds f64, team_saved_seconds f64, team_cpu_seconds f64.
//
// Decoding is written for hostile input (a network peer): every count is checked against the
// bytes that remain before anything is reserved, every id against what it indexes, positions
// must be finite, strings bounded, and trailing bytes are refused. A failure is
// Error(kInvalidInput) "subset job: byte N (section): what" (or "collapse records", "subset
// summary"). A decoded state has the shape the modules' imports rely on (see job_codec.cpp):
// strictly increasing ids, points under their face or vertex, distinct point ids, no vertex
// its own sharp neighbour, sample indices in range, wedge classes among the earlier wedges.
//
// Encoding throws Error(kInvalidInput) for what the layout cannot carry exactly: an unknown
// metric, ids not increasing, a state not in export order (module_state.h).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "simplify/simplifier.h"

namespace parapm {

std::string encode_subset_job(const SubsetJob& job);
// The job with `state` in place of its own, leaving out the state's items at `held_items`
// (indices in its order, increasing: its worker holds them): a held quadric's 11 numbers, a
// held point's all but its id (a job's energy state, with positions, only).
std::string encode_subset_job(const SubsetJob& job, const MetricState& state,
                              const std::vector<uint32_t>& held_items = {});
// Also runs validate_subset_job and checks the state against the job's mesh (ids in range,
// the attribute state E_scalar will need), so that simplify_subset can import it safely. The
// state's items at `held_items` (indices in its order, increasing) were left out: their
// quadrics, or their points' positions, distances, residuals and values, are left at zero,
// for the caller to put back (put_back_held_quadrics, put_back_held_points).
SubsetJob decode_subset_job(std::string_view bytes, const std::vector<uint32_t>& held_items = {});

// A list of strictly increasing ids (n v, ids+), and back: Error(kInvalidInput) "`what`: byte N
// ..." for ids not below `bound`, trailing bytes or a short list.
std::string encode_increasing_ids(const std::vector<uint32_t>& ids);
std::vector<uint32_t> decode_increasing_ids(std::string_view bytes, uint64_t bound,
                                            const char* what);

// One batch of records (a worker streams several); ids are the whole mesh's, checked by
// replay_collapses (collapse_merge.h) against the coordinator's mesh, which completes them.
std::string encode_collapse_records(const CollapseRecord* records, size_t count);
void decode_collapse_records(std::string_view bytes, std::vector<CollapseRecord>& append_to);

// Everything of a result but its records: round, subset, state, counts, stats and timings.
std::string encode_subset_summary(const SubsetResult& result);
// Fills all of `result` but its records (left as they are).
void decode_subset_summary(std::string_view bytes, SubsetResult& result);

}  // namespace parapm
