// The state of a priority module over part of a mesh, as plain data: what a subset job of the
// parallel construction (engine/parallel/subset_job.h) carries instead of initialising its
// metric anew, and what the job returns so that the master's module follows the round without
// re-running collapsed() on every record. Plain vectors of ids and numbers, so that the
// service layer can serialise it.
//
// Ids. Every face, vertex and wedge id in a state is the receiver's: an export translates
// through IdMaps (a job's local -> global maps, subset_job.h) in the direction the receiver
// needs: the master exports a job's part in the job's local ids (export_local), the job
// returns its part in global ids (export_global). Point and curve-sample ids are always the
// master's (global): a job numbers its points in state order and remembers their ids.
//
// Order. Lists whose order a module's arithmetic follows (a face's points, a vertex's sharp
// neighbours and listed curve samples) are written in their order, so that an imported
// module evaluates every edge to exactly the cost and position of the exporter.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "simplify/quadric.h"

namespace parapm {

// A job's local -> global ids, each strictly increasing (local i < j iff global i < j).
struct IdMaps {
  const std::vector<VertexId>* vertex = nullptr;
  const std::vector<FaceId>* face = nullptr;
  const std::vector<WedgeId>* wedge = nullptr;  // may be empty (no attributes)
};

struct QuadricState {
  std::vector<VertexId> vertices;
  std::vector<Quadric> quadrics;  // one per vertex above
};

struct EnergyState {
  struct Point {
    uint32_t id = 0;          // the master's point id
    FaceId face = kNoId;      // the face it projects onto; kNoId when parked
    VertexId vertex = kNoId;  // the vertex it is parked at (its sample), or kNoId
    Vec3 position{};
    double distance_sq = 0;
    double residual = 0;  // E_scalar's weighted squared attribute error (0 without)
  };
  struct CurveSample {
    uint32_t id = 0;  // the master's sample id
    Vec3 position{};
    double distance_sq = 0;
    VertexId u = kNoId, w = kNoId;  // the sharp edge it projects onto (w = kNoId: onto u)
  };
  // Whether the points' and curve samples' positions and the points' attribute values
  // (point_values) are present: a job's state carries them; a job's returned state does not
  // (they never change from where they were sampled, and the master holds them by id), and
  // its receiver reads none of them (their fields are left at zero and point_values empty).
  bool positions = true;
  // The faces the state covers: their point lists are exactly the points naming them, in the
  // order written (list order). A covered face without points has an empty list.
  std::vector<FaceId> faces;
  // The vertices it covers: their parked samples (the points naming them), sharp neighbours
  // and listed curve samples.
  std::vector<VertexId> vertices;
  std::vector<Point> points;          // face points grouped by face in list order, then parked
  std::vector<float> point_values;    // E_scalar: floats_per_wedge per point (empty without)
  std::vector<uint32_t> sharp_begin;  // per vertex, into sharp_neighbors (size vertices + 1)
  std::vector<VertexId> sharp_neighbors;
  std::vector<uint32_t> listed_begin;  // per vertex, into listed (size vertices + 1)
  std::vector<uint32_t> listed;        // indices into samples
  std::vector<CurveSample> samples;
  uint64_t curve_samples_total = 0;  // the exporter's sample count (whole mesh's on a job)
  // E_scalar: the covered wedges, their current values (floats_per_wedge each) and, per
  // wedge, a wedge of its class among `wedges` (the first one in that list): a class's
  // wedges all sit at one vertex, so covering a vertex's wedges covers its classes.
  std::vector<WedgeId> wedges;
  std::vector<float> wedge_values;
  std::vector<WedgeId> wedge_class;
};

// One direction of an IdMaps map: local -> global (to_local false), or global -> local
// (kNoId for an id the job does not hold; binary search, the map being increasing).
struct IdTranslation {
  const std::vector<uint32_t>* map = nullptr;
  bool to_local = false;
  uint32_t operator()(uint32_t id) const {
    if (id == kNoId) return kNoId;
    if (!to_local) return (*map)[id];
    const auto it = std::lower_bound(map->begin(), map->end(), id);
    return it != map->end() && *it == id ? uint32_t(it - map->begin()) : kNoId;
  }
  // The same, for an id expected near local position `hint` (the local id of a vertex whose
  // neighbour it is: the repair's spatial order keeps neighbours' ids close), by an
  // exponential search from there instead of a binary search over the whole map, whose
  // cache misses made a job's state export take as long as its simplification on a mesh
  // whose every edge is on a curve (openfoam-motorbike-332k).
  uint32_t near(uint32_t id, size_t hint) const {
    if (id == kNoId || !to_local) return (*this)(id);
    const std::vector<uint32_t>& m = *map;
    if (m.empty()) return kNoId;
    hint = std::min(hint, m.size() - 1);
    // The first position holding id or more lies in [lo, hi).
    size_t lo, hi;
    size_t step = 1;
    if (m[hint] < id) {
      while (hint + step < m.size() && m[hint + step] < id) step *= 2;
      lo = hint + step / 2 + 1;
      hi = std::min(m.size(), hint + step + 1);
    } else {
      while (step <= hint && m[hint - step] >= id) step *= 2;
      lo = step > hint ? 0 : hint - step + 1;
      hi = hint - step / 2 + 1;
    }
    const auto it = std::lower_bound(m.begin() + ptrdiff_t(lo), m.begin() + ptrdiff_t(hi), id);
    return it != m.end() && *it == id ? uint32_t(it - m.begin()) : kNoId;
  }
};

// What a job carries for its metric (the one of `metric`, the other part empty).
struct MetricState {
  std::string metric;  // "quadric", "energy", or empty: no state (the job initialises itself)
  QuadricState quadric;
  EnergyState energy;
  bool empty() const { return metric.empty(); }
};

}  // namespace parapm
