#include "parallel/live_pass.h"

#include <algorithm>
#include <atomic>
#include <utility>

#include "parallel/job_state.h"
#include "parallel/subset_job.h"
#include "simplify/energy_priority.h"
#include "simplify/modules.h"
#include "simplify/quadric_priority.h"
#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm {
namespace {

// Per vertex of the copy, the whole mesh's value of its vertex (empty stays empty).
template <typename T>
std::vector<T> of_copy(const std::vector<T>& whole, const std::vector<VertexId>& global) {
  std::vector<T> out;
  if (whole.empty()) return out;
  out.reserve(global.size());
  for (VertexId g : global) out.push_back(whole[g]);
  return out;
}

// The live part of `whole` as a job of one subset owning it all, without a halo (subset_job.h:
// local ids in the global order), its passes in `loops`' chunks; false when a live vertex holds
// no face. Only what the pass reads is filled: the mesh, the maps, the locks and the groups.
bool copy_live_part(const CollapseMesh& whole, const LivePassInputs& inputs, ChunkedLoops& loops,
                    SubsetJob& copy, KeptItems& vertices, KeptItems& faces) {
  vertices = number_kept(loops, whole.vertex_capacity(),
                         [&](size_t v) { return whole.vertex_alive(VertexId(v)); });
  faces = number_kept(loops, whole.face_capacity(),
                      [&](size_t f) { return whole.face_alive(FaceId(f)); });
  Mesh& mesh = copy.mesh;
  mesh.positions_are_float = inputs.positions_are_float;
  resize_touched(mesh.positions, vertices.old_id.size(), loops);
  loops.run(vertices.old_id.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) mesh.positions[i] = whole.position(vertices.old_id[i]);
  });
  std::vector<uint8_t> held(vertices.old_id.size(), 0);
  resize_touched(mesh.faces, faces.old_id.size(), loops);
  loops.run(faces.old_id.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const Triangle& t = whole.face(faces.old_id[i]);
      for (int k = 0; k < 3; ++k) {
        mesh.faces[i][k] = vertices.new_id[t[k]];
        std::atomic_ref<uint8_t>(held[mesh.faces[i][k]]).store(1, std::memory_order_relaxed);
      }
    }
  });
  if (std::find(held.begin(), held.end(), 0) != held.end()) return false;
  copy.global_vertex = vertices.old_id;
  copy.global_face = faces.old_id;
  if (inputs.locked) copy.locked = of_copy(*inputs.locked, copy.global_vertex);
  copy.locked.resize(copy.global_vertex.size(), 0);
  const CopyGroups* groups = inputs.groups;
  if (groups && !groups->empty()) {
    // Every live copy is here: a group is named by its first live copy's local id.
    copy.copy_group.assign(copy.global_vertex.size(), kNoId);
    for (size_t i = 0; i < copy.global_vertex.size(); ++i) {
      const VertexId g = copy.global_vertex[i];
      if (!groups->is_copy(g)) continue;
      for (VertexId member : groups->of(groups->group[g]))
        if (whole.vertex_alive(member)) {
          copy.copy_group[i] = vertices.new_id[member];
          break;
        }
    }
  }
  const size_t floats = size_t(inputs.layout->floats_per_wedge());
  if (inputs.layout->any() && whole.has_wedges() && floats > 0) {
    // The wedges of the live faces' corners, numbered in order.
    std::vector<uint8_t> used(inputs.wedge_values->size() / floats, 0);
    loops.run(faces.old_id.size(), [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i)
        for (WedgeId w : whole.corner_wedges(faces.old_id[i]))
          std::atomic_ref<uint8_t>(used[w]).store(1, std::memory_order_relaxed);
    });
    const KeptItems wedges = number_kept(loops, used.size(), [&](size_t w) { return used[w]; });
    copy.global_wedge = wedges.old_id;
    mesh.layout = *inputs.layout;
    mesh.wedge_values.resize(wedges.old_id.size() * floats);
    for (size_t i = 0; i < wedges.old_id.size(); ++i)
      std::copy_n(inputs.wedge_values->begin() + ptrdiff_t(wedges.old_id[i] * floats), floats,
                  mesh.wedge_values.begin() + ptrdiff_t(i * floats));
    mesh.wedge_vertex.assign(wedges.old_id.size(), kNoId);
    mesh.face_wedges.resize(faces.old_id.size());
    for (size_t i = 0; i < faces.old_id.size(); ++i) {
      const auto& w = whole.corner_wedges(faces.old_id[i]);
      for (int k = 0; k < 3; ++k) {
        mesh.face_wedges[i][k] = wedges.new_id[w[k]];
        mesh.wedge_vertex[mesh.face_wedges[i][k]] = mesh.faces[i][k];
      }
    }
  }
  return true;
}

// `master`'s state over the copy, carried over as a job's is, in a module of the master's
// options: the quadric's (its free placement's line is the input's face count's), the energy's
// with its faces' drifts (read straight from the master where no attributes travel with the
// points: EnergyPriority::import_from). `loops`: the energy's points' passes.
std::unique_ptr<PriorityModule> module_of_copy(const PriorityModule& master,
                                               const LivePassInputs& inputs, SubsetJob& copy,
                                               const CollapseMesh& mesh, ChunkedLoops& loops) {
  copy.owned.assign(copy.global_vertex.size(), 1);
  if (const auto* quadric = dynamic_cast<const QuadricPriority*>(&master)) {
    auto module = std::make_unique<QuadricPriority>(copy.locked, quadric->options());
    copy.state = export_job_state(master, copy);
    import_job_state(*module, mesh, copy);
    copy.state = MetricState{};
    return module;
  }
  const auto& energy = dynamic_cast<const EnergyPriority&>(master);
  std::unique_ptr<PriorityModule> made =
      make_priority_module(*inputs.options, copy.mesh, copy.locked, inputs.reference_diagonal);
  auto& module = dynamic_cast<EnergyPriority&>(*made);
  const IdMaps maps{&copy.global_vertex, &copy.global_face, &copy.global_wedge};
  if (imports_from_master(master, copy)) {
    module.import_from(energy, mesh, maps, true, loops);
    return made;
  }
  std::vector<double> drifts;
  module.import_local(mesh, energy.export_with_drifts(maps, loops, drifts), loops);
  module.set_drifts(drifts);
  return made;
}

// The whole mesh's edges (global ids, sorted) in the copy's ids, those with an end outside it
// left out (still sorted: local ids follow the global order).
template <typename Edge>
std::vector<Edge> edges_in_copy(const std::vector<Edge>* edges,
                                const std::vector<uint32_t>& vertex_in_copy) {
  std::vector<Edge> out;
  if (!edges) return out;
  out.reserve(edges->size());
  for (Edge e : *edges) {
    if (e.a >= vertex_in_copy.size() || e.b >= vertex_in_copy.size()) continue;
    e.a = vertex_in_copy[e.a];
    e.b = vertex_in_copy[e.b];
    if (e.a != kNoKey && e.b != kNoKey) out.push_back(e);
  }
  return out;
}

}  // namespace

bool runs_on_live_copy(const PriorityModule& master) {
  return dynamic_cast<const QuadricPriority*>(&master) ||
         dynamic_cast<const EnergyPriority*>(&master);
}

std::optional<LivePass> run_on_live_copy(const CollapseMesh& whole, const PriorityModule& master,
                                         const LivePassInputs& inputs,
                                         const SimplifierLimits& limits,
                                         const ProgressCallback& progress,
                                         const CancelToken* cancel, ChunkedLoops& loops) {
  if (!runs_on_live_copy(master))
    throw_internal("run_on_live_copy: no copy of metric " + master.name());
  SubsetJob copy;
  KeptItems vertices, faces;
  if (!copy_live_part(whole, inputs, loops, copy, vertices, faces)) return std::nullopt;

  LivePass out;
  out.mesh = std::make_unique<CollapseMesh>(copy.mesh, loops);
  CollapseMesh& mesh = *out.mesh;
  // Each fan in the whole mesh's order (the collapses' order, not the faces' ids).
  loops.run(copy.global_vertex.size(), [&](size_t begin, size_t end) {
    std::vector<FaceId> fan;
    for (size_t v = begin; v < end; ++v) {
      fan.clear();
      for (FaceId f : whole.faces_of(copy.global_vertex[v])) fan.push_back(faces.new_id[f]);
      mesh.order_faces_of(VertexId(v), fan);
    }
  });
  const std::unique_ptr<PriorityModule> module = module_of_copy(master, inputs, copy, mesh, loops);
  copy.mesh = Mesh{};  // (the working mesh holds it)
  if (inputs.team) module->use_team(inputs.team);
  const std::unique_ptr<PriorityModule> imported = without_initialize(*module);
  std::optional<KeyMemo> memo;
  if (inputs.keys) {
    memo.emplace(*imported, mesh.vertex_capacity());
    memo->reset(edges_in_copy(inputs.keys, vertices.new_id));
  }
  std::unique_ptr<PriorityModule> continued =
      memo ? without_initialize(*memo) : std::unique_ptr<PriorityModule>{};
  PriorityModule& priority = continued ? *continued : *imported;

  std::shared_ptr<const std::vector<uint32_t>> components;
  if (inputs.components)
    components = std::make_shared<const std::vector<uint32_t>>(
        of_copy(*inputs.components, copy.global_vertex));
  Simplifier pass(
      mesh, priority,
      standard_constraints(copy.locked, std::move(components), inputs.components_may_vanish,
                           inputs.on_membrane ? of_copy(*inputs.on_membrane, copy.global_vertex)
                                              : std::vector<uint8_t>{}));
  const CopyGroups groups = copy_groups_of(copy.copy_group);
  if (!groups.empty()) pass.join_copies(&groups);
  const std::vector<DeferredEdge> deferred = edges_in_copy(inputs.deferred, vertices.new_id);
  SimplifierLimits copy_limits = limits;
  copy_limits.first_deferred = &deferred;

  out.records = pass.run(copy_limits, progress, cancel);
  for (CollapseRecord& r : out.records) to_global_ids(r, copy);
  out.stats = pass.stats();
  out.costings = module->costings();
  out.keys_reused = memo ? memo->reused() : 0;
  out.vertex_in_copy = std::move(vertices.new_id);
  out.face_in_copy = std::move(faces.new_id);
  out.vertex_of_copy = std::move(copy.global_vertex);
  return out;
}

}  // namespace parapm
