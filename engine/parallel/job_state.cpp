#include "parallel/job_state.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <string>

#include "parallel/simplify_subset.h"
#include "parallel/subset_rule.h"
#include "util/clock.h"
#include "util/job_pool.h"

#include "simplify/energy_priority.h"
#include "simplify/quadric_priority.h"
#include "util/error.h"

namespace parapm {
namespace {

IdMaps maps_of(const SubsetJob& job) {
  return {&job.global_vertex, &job.global_face, &job.global_wedge};
}

bool metric_returns_state(const std::string& metric) { return metric != "quadric"; }

class WithoutInitialize : public PriorityWrapper {
 public:
  using PriorityWrapper::PriorityWrapper;
  void initialize(const CollapseMesh&) override {}
  void evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                     Costing costing) override {
    inner_.evaluate_each(mesh, edges, costing);
  }
  void evaluate_seam_at(const CollapseMesh& mesh, std::span<const SeamPair> pairs,
                        std::span<const Vec3> places, Costing costing,
                        std::span<SeamCosting> out) override {
    inner_.evaluate_seam_at(mesh, pairs, places, costing, out);
  }
};

}  // namespace

bool job_state_needed(const PriorityModule& master, uint32_t round) {
  return round > 0 || !dynamic_cast<const QuadricPriority*>(&master);
}

bool returns_state(const PriorityModule& module) { return metric_returns_state(module.name()); }

std::string returned_state_metric(const SubsetJob& job) {
  return job.state.empty() || !metric_returns_state(job.state.metric) ? "" : job.state.metric;
}

MetricState export_job_state(const PriorityModule& master, const SubsetJob& job,
                             ChunkedLoops* loops) {
  ChunkedLoops plain;
  MetricState state;
  state.metric = master.name();
  if (const auto* q = dynamic_cast<const QuadricPriority*>(&master)) {
    const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
    state.quadric = q->export_local(maps_of(job), &free);
  } else if (const auto* e = dynamic_cast<const EnergyPriority*>(&master)) {
    state.energy = e->export_local(maps_of(job), loops ? *loops : plain);
  } else {
    throw_internal("export_job_state: no state export for metric " + master.name());
  }
  return state;
}

void import_job_state(PriorityModule& module, const CollapseMesh& mesh, const SubsetJob& job,
                      ChunkedLoops* loops) {
  ChunkedLoops plain;
  if (job.state.metric != module.name())
    throw_invalid("subset job " + std::to_string(job.subset) + ": its state is of metric '" +
                  job.state.metric + "', the job's metric is " + module.name());
  if (auto* q = dynamic_cast<QuadricPriority*>(&module)) {
    q->import_local(mesh, job.state.quadric);
  } else if (auto* e = dynamic_cast<EnergyPriority*>(&module)) {
    e->import_local(mesh, job.state.energy, loops ? *loops : plain);
  } else {
    throw_internal("import_job_state: no state import for metric " + module.name());
  }
}

bool imports_from_master(const PriorityModule& master, const SubsetJob& job) {
  const auto* energy = dynamic_cast<const EnergyPriority*>(&master);
  return energy && !energy->carries_attributes() && !job.mesh.layout.any();
}

void import_from_master(PriorityModule& module, const CollapseMesh& mesh, const SubsetJob& job,
                        const PriorityModule& master, ChunkedLoops* loops) {
  ChunkedLoops plain;
  auto* energy = dynamic_cast<EnergyPriority*>(&module);
  const auto* from = dynamic_cast<const EnergyPriority*>(&master);
  if (!energy || !from)
    throw_internal("import_from_master: no direct import of metric " + master.name());
  energy->import_from(*from, mesh, maps_of(job), false, loops ? *loops : plain);
}

MetricState export_result_state(const PriorityModule& module, const CollapseMesh& mesh,
                                const SubsetJob& job, const std::vector<CollapseRecord>& records,
                                ChunkedLoops* loops) {
  ChunkedLoops plain;
  if (!returns_state(module)) return {};
  std::vector<uint8_t> changed(mesh.vertex_capacity(), 0);
  for (const CollapseRecord& r : records) {
    if (r.vs >= changed.size() || r.vt >= changed.size() || !job.owned[r.vs] || !job.owned[r.vt])
      throw_internal("export_result_state: a collapse of vertices the job does not own");
    changed[r.vs] = changed[r.vt] = 1;
  }
  MetricState state;
  state.metric = module.name();
  if (const auto* e = dynamic_cast<const EnergyPriority*>(&module)) {
    state.energy = e->export_global(mesh, maps_of(job), changed, loops ? *loops : plain);
  } else {
    throw_internal("export_result_state: no state export for metric " + module.name());
  }
  return state;
}

void import_result_state(PriorityModule& master, const MetricState& state,
                         const std::vector<CollapseRecord>& records) {
  if (auto* q = dynamic_cast<QuadricPriority*>(&master)) {
    if (!state.empty()) throw_invalid("a quadric job returns no state; this result has one");
    q->check_records(records, 0, nullptr);
    q->follow_records(records);
    return;
  }
  if (state.metric != master.name())
    throw_internal("import_result_state: a state of metric '" + state.metric + "' for " +
                   master.name());
  if (auto* e = dynamic_cast<EnergyPriority*>(&master)) {
    e->import_global(state.energy);
  } else {
    throw_internal("import_result_state: no state import for metric " + master.name());
  }
}

void check_state_covers(const MetricState& state, const std::vector<CollapseRecord>& records) {
  if (state.metric != "energy")
    throw_internal("check_state_covers: no state of metric '" + state.metric + "'");
  const std::vector<VertexId>& vertices = state.energy.vertices;
  const std::vector<FaceId>& faces = state.energy.faces;
  auto increasing = [](const std::vector<uint32_t>& ids) {
    return std::adjacent_find(ids.begin(), ids.end(), std::greater_equal<>()) == ids.end();
  };
  if (!increasing(vertices) || !increasing(faces))
    throw_invalid(state.metric + " state: its vertex or face list is not in increasing order");
  for (size_t i = 0; i < records.size(); ++i) {
    const CollapseRecord& r = records[i];
    for (VertexId v : {r.vs, r.vt})
      if (!std::binary_search(vertices.begin(), vertices.end(), v))
        throw_invalid(state.metric + " state: does not cover vertex " + std::to_string(v) +
                      ", an end of its job's collapse " + std::to_string(i));
    for (FaceId f : {r.fl, r.fr})
      if (f != kNoId && !std::binary_search(faces.begin(), faces.end(), f))
        throw_invalid("energy state: does not cover face " + std::to_string(f) +
                      ", removed by its job's collapse " + std::to_string(i));
  }
}

ImportTimes import_result_states(PriorityModule& master,
                                 const std::vector<const MetricState*>& states,
                                 const std::vector<uint32_t>& vertex_subset,
                                 const std::vector<uint32_t>& face_subset, unsigned threads,
                                 const std::vector<const std::vector<CollapseRecord>*>& records,
                                 unsigned cores) {
  const auto start = std::chrono::steady_clock::now();
  ImportTimes times;
  auto* quadric = dynamic_cast<QuadricPriority*>(&master);
  for (const MetricState* state : states)
    if (quadric ? !state->empty() : state->metric != master.name())
      throw_invalid("import_result_states: a state of metric '" + state->metric + "' for " +
                    master.name() + (quadric ? " (whose jobs return none)" : ""));
  if (quadric && records.size() != states.size())
    throw_internal("import_result_states: the quadric follows its jobs' records; none given");
  if (!records.empty() && records.size() != states.size())
    throw_internal("import_result_states: " + std::to_string(records.size()) +
                   " record lists for " + std::to_string(states.size()) + " states");
  std::vector<double> check_cpu(states.size(), 0), apply_cpu(states.size(), 0);
  // Per state, its passes' chunks on the cores fewer states leave.
  std::vector<ChunkedLoops> loops(states.size(),
                                  state_loops_of(team_of_round(states.size(), cores, threads, 0)));
  // Each step on the pool, each state's CPU timed (its chunks at their slowest); a state's
  // check ends with its coverage.
  auto side_by_side = [&](std::vector<double>& cpu, const std::function<void(size_t)>& step) {
    run_jobs(states.size(), threads, [&](size_t k) {
      const double t = thread_cpu_seconds();
      const double saved = loops[k].seconds() - loops[k].critical_seconds();
      step(k);
      cpu[k] =
          thread_cpu_seconds() - t - (loops[k].seconds() - loops[k].critical_seconds() - saved);
    });
  };
  auto covers = [&](size_t k) {
    if (!records.empty()) check_state_covers(*states[k], *records[k]);
  };
  double sequential = 0;
  if (quadric) {
    side_by_side(check_cpu, [&](size_t k) {
      quadric->check_records(*records[k], uint32_t(k), &vertex_subset);
    });
    side_by_side(apply_cpu, [&](size_t k) { quadric->follow_records(*records[k]); });
  } else if (auto* e = dynamic_cast<EnergyPriority*>(&master)) {
    const auto begin = std::chrono::steady_clock::now();
    e->begin_global_imports();
    sequential += seconds_since(begin);
    const EnergyPriority::GlobalOwners owners{&vertex_subset, &face_subset};
    std::vector<EnergyPriority::GlobalImport> imports(states.size());
    side_by_side(check_cpu, [&](size_t k) {
      imports[k] = e->check_global(states[k]->energy, uint32_t(k), owners, loops[k]);
      covers(k);
    });
    side_by_side(apply_cpu,
                 [&](size_t k) { e->apply_global(states[k]->energy, imports[k], loops[k]); });
    const auto wedges = std::chrono::steady_clock::now();
    for (const MetricState* state : states) e->apply_global_wedges(state->energy);
    sequential += seconds_since(wedges);
  } else {
    throw_internal("import_result_states: no state import for metric " + master.name());
  }
  times.seconds = seconds_since(start);
  for (size_t k = 0; k < states.size(); ++k) {
    times.slowest_check_seconds = std::max(times.slowest_check_seconds, check_cpu[k]);
    times.slowest_apply_seconds = std::max(times.slowest_apply_seconds, apply_cpu[k]);
  }
  times.critical_seconds = sequential + times.slowest_check_seconds + times.slowest_apply_seconds;
  return times;
}

std::unique_ptr<PriorityModule> without_initialize(PriorityModule& inner) {
  return std::make_unique<WithoutInitialize>(inner);
}

}  // namespace parapm
