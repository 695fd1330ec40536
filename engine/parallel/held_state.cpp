#include "parallel/held_state.h"

#include <algorithm>
#include <bit>
#include <string>

#include "parallel/simplify_subset.h"
#include "parallel/subset_rule.h"
#include "simplify/quadric_priority.h"
#include "util/error.h"

namespace parapm {
namespace {

// splitmix64's finaliser: every input bit reaches every output bit.
uint64_t mix(uint64_t x) {
  x ^= x >> 30;
  x *= 0xbf58476d1ce4e5b9ULL;
  x ^= x >> 27;
  x *= 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

}  // namespace

uint64_t quadric_fingerprint(const Quadric& q) {
  uint64_t h = 0x51ad41c5ULL;
  for (double x : {q.a00, q.a01, q.a02, q.a11, q.a12, q.a22, q.b0, q.b1, q.b2, q.c, q.weight})
    h = mix(h ^ std::bit_cast<uint64_t>(x));
  return h;
}

uint64_t quadrics_fingerprint(const std::vector<Quadric>& quadrics) {
  std::vector<uint64_t> fingerprints(quadrics.size());
  for (size_t i = 0; i < quadrics.size(); ++i) fingerprints[i] = quadric_fingerprint(quadrics[i]);
  return fingerprints_fingerprint(fingerprints);
}

QuadricState initial_free_quadrics(const SubsetJob& job) {
  QuadricState out;
  if (job.options.metric != "quadric") return out;
  if (!job.state.empty()) {
    out = job.state.quadric;
  } else {
    // What the job's simplifier does first: initialise its module on its working mesh.
    const CollapseMesh working(job.mesh);
    const std::unique_ptr<PriorityModule> module = job_module(job, working);
    module->initialize(working);
    const auto* quadrics = dynamic_cast<const QuadricPriority*>(module.get());
    if (!quadrics) throw_internal("initial_free_quadrics: the quadric job's module is another");
    const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
    for (VertexId v = 0; v < free.size(); ++v)
      if (free[v]) {
        out.vertices.push_back(v);
        out.quadrics.push_back(quadrics->quadric(v));
      }
  }
  for (VertexId& v : out.vertices) {
    if (v >= job.global_vertex.size())
      throw_invalid("quadric state: vertex " + std::to_string(v) + " out of the job's range");
    v = job.global_vertex[v];
  }
  return out;
}

void follow_records(QuadricState& quadrics, const std::vector<CollapseRecord>& records) {
  const std::vector<VertexId>& ids = quadrics.vertices;
  auto index_of = [&](VertexId v, size_t record) {
    const auto it = std::lower_bound(ids.begin(), ids.end(), v);
    if (it == ids.end() || *it != v)
      throw_invalid("collapse " + std::to_string(record) + ": vertex " + std::to_string(v) +
                    " is not a free vertex of its job");
    return size_t(it - ids.begin());
  };
  for (size_t i = 0; i < records.size(); ++i) {
    const size_t s = index_of(records[i].vs, i), t = index_of(records[i].vt, i);
    quadrics.quadrics[s] += quadrics.quadrics[t];
  }
}

void put_back_held_quadrics(QuadricState& state, const std::vector<uint32_t>& held,
                            const std::vector<Quadric>& quadrics) {
  if (held.size() != quadrics.size())
    throw_invalid("held quadrics: " + std::to_string(held.size()) + " indices, " +
                  std::to_string(quadrics.size()) + " quadrics");
  for (size_t j = 0; j < held.size(); ++j) {
    if (held[j] >= state.quadrics.size())
      throw_invalid("held quadric " + std::to_string(held[j]) + " past the job's quadrics");
    state.quadrics[held[j]] = quadrics[j];
  }
}

std::vector<std::pair<uint32_t, uint64_t>> holdable_items(const SubsetJob& job) {
  std::vector<std::pair<uint32_t, uint64_t>> items;
  if (job.state.metric == "quadric") {
    const QuadricState& q = job.state.quadric;
    items.reserve(q.vertices.size());
    for (size_t k = 0; k < q.vertices.size(); ++k) {
      if (q.vertices[k] >= job.global_vertex.size())
        throw_invalid("quadric state: vertex " + std::to_string(q.vertices[k]) +
                      " out of the job's range");
      items.emplace_back(job.global_vertex[q.vertices[k]], quadric_fingerprint(q.quadrics[k]));
    }
  } else if (job.state.metric == "energy" && job.state.energy.positions) {
    const EnergyState& e = job.state.energy;
    items.reserve(e.points.size());
    for (size_t i = 0; i < e.points.size(); ++i)
      items.emplace_back(e.points[i].id, point_fingerprint(e, i));
  }
  return items;
}

uint64_t point_fingerprint(const HeldPoint& point, const float* values, size_t k) {
  uint64_t h = 0x9017e5ULL;
  for (double c : point.position) h = mix(h ^ std::bit_cast<uint64_t>(c));
  h = mix(h ^ std::bit_cast<uint64_t>(point.distance_sq));
  h = mix(h ^ std::bit_cast<uint64_t>(point.residual));
  for (size_t j = 0; j < k; ++j) h = mix(h ^ std::bit_cast<uint32_t>(values[j]));
  return h;
}

uint64_t point_fingerprint(const EnergyState& state, size_t i) {
  const size_t k = state.points.empty() ? 0 : state.point_values.size() / state.points.size();
  const EnergyState::Point& p = state.points[i];
  return point_fingerprint({p.position, p.distance_sq, p.residual},
                           state.point_values.data() + i * k, k);
}

uint64_t fingerprints_fingerprint(const std::vector<uint64_t>& fingerprints) {
  uint64_t h = mix(fingerprints.size());
  for (uint64_t f : fingerprints) h = mix(h ^ f);
  return h;
}

std::vector<std::pair<uint32_t, uint64_t>> held_items_after(const SubsetJob& job,
                                                            const EnergyState& returned) {
  const EnergyState& sent = job.state.energy;
  if (job.state.metric != "energy" || !sent.positions) return {};
  // The returned points' distances and residuals, by id.
  std::vector<std::pair<uint32_t, uint32_t>> by_id(returned.points.size());
  for (uint32_t i = 0; i < by_id.size(); ++i) by_id[i] = {returned.points[i].id, i};
  std::sort(by_id.begin(), by_id.end());
  const size_t k = sent.points.empty() ? 0 : sent.point_values.size() / sent.points.size();
  std::vector<std::pair<uint32_t, uint64_t>> items(sent.points.size());
  for (size_t i = 0; i < sent.points.size(); ++i) {
    const EnergyState::Point& p = sent.points[i];
    HeldPoint held{p.position, p.distance_sq, p.residual};
    const auto it = std::lower_bound(by_id.begin(), by_id.end(), std::pair{p.id, 0u});
    if (it != by_id.end() && it->first == p.id) {
      held.distance_sq = returned.points[it->second].distance_sq;
      held.residual = returned.points[it->second].residual;
    }
    items[i] = {p.id, point_fingerprint(held, sent.point_values.data() + i * k, k)};
  }
  return items;
}

void put_back_held_points(EnergyState& state, const std::vector<uint32_t>& held,
                          const std::vector<HeldPoint>& points, const std::vector<float>& values) {
  const size_t k = state.points.empty() ? 0 : state.point_values.size() / state.points.size();
  if (points.size() != held.size() || values.size() != held.size() * k)
    throw_invalid("held points: " + std::to_string(held.size()) + " indices, " +
                  std::to_string(points.size()) + " points");
  for (size_t j = 0; j < held.size(); ++j) {
    const size_t i = held[j];
    if (i >= state.points.size())
      throw_invalid("held point " + std::to_string(i) + " past the job's points");
    state.points[i].position = points[j].position;
    state.points[i].distance_sq = points[j].distance_sq;
    state.points[i].residual = points[j].residual;
    std::copy_n(values.begin() + ptrdiff_t(j * k), k,
                state.point_values.begin() + ptrdiff_t(i * k));
  }
}

}  // namespace parapm
