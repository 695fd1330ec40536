// The Progressive Mesh (Hoppe 96): a base mesh M0 and an ordered list of vertex splits that
// rebuild M0 -> M1 -> ... -> Mn, where Mn is the input (after the documented repairs).
//
// Numbering (Hoppe's convention, which makes a PM streamable):
//  - vertices: the base mesh has ids 0..n0-1; vsplit i creates vertex vt = n0 + i.
//  - faces: the base mesh has ids 0..f0-1; vsplit i appends fl, then fr (each when present).
//  - wedges: the base mesh's wedges are 0..w0-1; vsplit i introduces `new_wedge_count`
//    wedges with the next ids (values in new_wedge_values).
//
// The geometry of vsplit i, in the mesh before it is applied (vs present, vt not yet):
//   fl = (vs, vt, vl) and fr = (vt, vs, vr) are the two new faces, counter-clockwise; either
//   may be absent on a boundary (vl or vr == kNoId), never both. The faces of vs that move
//   to vt are the fan that starts at the face holding the directed edge vs->vr and turns
//   counter-clockwise around vs up to the face holding vl->vs; where vt was a boundary
//   vertex the fan is cut by the boundary and is walked from both ends (see fan_mesh.cpp).
//   Their corners at vs become corners at vt; corner wedges do not change. A vs without
//   faces has an empty fan, and vl and vr (when present) have no faces either: the split
//   brings back a component whose last faces were collapsed away, as fl and fr.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

class ChunkedLoops;

struct VertexSplit {
  VertexId vs = kNoId;
  VertexId vl = kNoId;  // third corner of fl, or kNoId
  VertexId vr = kNoId;  // third corner of fr, or kNoId
  // Error bound of the level this split leaves, in model units: a non-increasing sequence
  // along the splits (running maximum of the collapse costs, see the simplifier), so that
  // cutting at error E means applying every split whose error is > E.
  float error = 0;
  Vec3 vs_before{};  // position of vs before the split
  Vec3 vs_after{};   // position of vs after the split
  Vec3 vt_after{};   // position of the new vertex vt
  // Corner wedges of the new faces, in the corner order above: fl (vs, vt, vl), fr (vt, vs,
  // vr); kNoId for an absent face or a mesh without attributes.
  std::array<WedgeId, 6> corner_wedges{kNoId, kNoId, kNoId, kNoId, kNoId, kNoId};
  uint32_t new_wedge_count = 0;      // wedges introduced by this split
  uint32_t wedge_changes_begin = 0;  // index into ProgressiveMesh::wedge_changes
  uint32_t wedge_changes_count = 0;

  bool has_fl() const { return vl != kNoId; }
  bool has_fr() const { return vr != kNoId; }
  int new_faces() const { return int(has_fl()) + int(has_fr()); }
};

// A wedge whose attribute values differ above and below a split (the simplifier moved it).
struct WedgeChange {
  WedgeId wedge = kNoId;
  uint32_t values_offset = 0;  // into wedge_change_values: floats_per_wedge coarse, then fine
};

struct PmInfo {
  std::string metric;           // "quadric", "energy"
  uint64_t input_vertices = 0;  // of the input as read, before repairs
  uint64_t input_faces = 0;     // triangles of the input as read (polygons fan-split)
  double seconds = 0;           // construction time; in memory only (not in the .pm, whose
                                // bytes depend only on the input and the options)
};

struct ProgressiveMesh {
  Mesh base;  // M0; base.wedge_vertex is filled when the mesh has attributes
  std::vector<VertexSplit> splits;
  std::vector<float> new_wedge_values;  // floats_per_wedge per introduced wedge, in id order
  std::vector<WedgeChange> wedge_changes;
  std::vector<float> wedge_change_values;

  // Restoring the input exactly at full resolution:
  // (copy, original) pairs in full-resolution vertex ids: vertices the repair step split off
  // non-manifold vertices; merging each copy into its original gives back the input.
  std::vector<std::pair<VertexId, VertexId>> vertex_copies;
  // Optional (--keep-order): full-resolution vertex id -> input vertex index, and face id ->
  // input face index. Empty when the order was not kept.
  std::vector<uint32_t> input_vertex_order;
  std::vector<uint32_t> input_face_order;

  PmInfo info;

  size_t full_vertex_count() const { return base.vertex_count() + splits.size(); }
  size_t full_face_count() const;
  size_t full_wedge_count() const;
};

// Checks the invariants of a PM (ids in range, new wedges consistent, errors
// non-increasing, copies and orders are permutations of the right size); throws
// Error(kInvalidInput) naming the first violation. Readers of untrusted .pm files call it.
void validate_pm(const ProgressiveMesh& pm);
// The same checks and the same error, each split's own checks in `loops`' chunks side by side
// and the replay of positions and wedge values after them, in one pass.
void validate_pm(const ProgressiveMesh& pm, ChunkedLoops& loops);

}  // namespace parapm
