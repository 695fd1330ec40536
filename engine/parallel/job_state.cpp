#include "parallel/job_state.h"

#include "simplify/energy_priority.h"
#include "simplify/quadric_priority.h"
#include "util/error.h"

namespace parapm {
namespace {

IdMaps maps_of(const SubsetJob& job) {
  return {&job.global_vertex, &job.global_face, &job.global_wedge};
}

class WithoutInitialize : public PriorityWrapper {
 public:
  using PriorityWrapper::PriorityWrapper;
  void initialize(const CollapseMesh&) override {}
};

}  // namespace

MetricState export_job_state(const PriorityModule& master, const SubsetJob& job) {
  MetricState state;
  state.metric = master.name();
  if (const auto* q = dynamic_cast<const QuadricPriority*>(&master)) {
    state.quadric = q->export_local(maps_of(job));
  } else if (const auto* e = dynamic_cast<const EnergyPriority*>(&master)) {
    state.energy = e->export_local(maps_of(job));
  } else {
    throw_internal("export_job_state: no state export for metric " + master.name());
  }
  return state;
}

void import_job_state(PriorityModule& module, const CollapseMesh& mesh, const SubsetJob& job) {
  if (job.state.metric != module.name())
    throw_invalid("subset job " + std::to_string(job.subset) + ": its state is of metric '" +
                  job.state.metric + "', the job's metric is " + module.name());
  if (auto* q = dynamic_cast<QuadricPriority*>(&module)) {
    q->import_local(mesh, job.state.quadric);
  } else if (auto* e = dynamic_cast<EnergyPriority*>(&module)) {
    e->import_local(mesh, job.state.energy);
  } else {
    throw_internal("import_job_state: no state import for metric " + module.name());
  }
}

MetricState export_result_state(const PriorityModule& module, const CollapseMesh& mesh,
                                const SubsetJob& job, const std::vector<CollapseRecord>& records) {
  std::vector<uint8_t> changed(mesh.vertex_capacity(), 0);
  for (const CollapseRecord& r : records) {
    if (r.vs >= changed.size() || r.vt >= changed.size() || !job.owned[r.vs] || !job.owned[r.vt])
      throw_internal("export_result_state: a collapse of vertices the job does not own");
    changed[r.vs] = changed[r.vt] = 1;
  }
  MetricState state;
  state.metric = module.name();
  if (const auto* q = dynamic_cast<const QuadricPriority*>(&module)) {
    state.quadric = q->export_global(maps_of(job), changed);
  } else if (const auto* e = dynamic_cast<const EnergyPriority*>(&module)) {
    state.energy = e->export_global(mesh, maps_of(job), changed);
  } else {
    throw_internal("export_result_state: no state export for metric " + module.name());
  }
  return state;
}

void import_result_state(PriorityModule& master, const MetricState& state) {
  if (state.metric != master.name())
    throw_internal("import_result_state: a state of metric '" + state.metric + "' for " +
                   master.name());
  if (auto* q = dynamic_cast<QuadricPriority*>(&master)) {
    q->import_global(state.quadric);
  } else if (auto* e = dynamic_cast<EnergyPriority*>(&master)) {
    e->import_global(state.energy);
  } else {
    throw_internal("import_result_state: no state import for metric " + master.name());
  }
}

std::unique_ptr<PriorityModule> without_initialize(PriorityModule& inner) {
  return std::make_unique<WithoutInitialize>(inner);
}

}  // namespace parapm
