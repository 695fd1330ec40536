// The parallel build's final pass run on a compact copy of the live mesh. By the final pass a
// tenth of the input's faces are left, scattered over the whole mesh's arrays (each live vertex
// and face on a cache line of its own, beside dead ones); on a copy of just them, whose local
// ids follow the global order (subset_job.h: ties fall as on the whole mesh) and whose fans
// list their faces in the whole mesh's order (the energy's points go to the first of equally
// near faces), the same collapses cost fewer cache misses. The master's state is carried over
// as a job's is (job_state.h), the energy's faces with their drifts, and with the queue keys
// and deferred edges the pass on the whole mesh would start from; the records come back in the
// whole mesh's ids, the same records the pass on the whole mesh makes.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "mesh/mesh.h"
#include "parallel/edge_keys.h"
#include "simplify/collapse_mesh.h"
#include "simplify/copy_groups.h"
#include "simplify/pm_builder.h"
#include "simplify/simplifier.h"
#include "simplify/simplify.h"
#include "util/chunked_loops.h"
#include "util/progress.h"
#include "util/thread_team.h"

namespace parapm {

// What the pass on the whole mesh is given, per vertex of the whole mesh where per vertex.
struct LivePassInputs {
  const AttributeLayout* layout = nullptr;
  // The input's wedge values (the energy's current ones travel in its state).
  const std::vector<float>* wedge_values = nullptr;
  bool positions_are_float = false;
  const std::vector<uint8_t>* locked = nullptr;  // may be empty
  const CopyGroups* groups = nullptr;            // may be empty
  // connected_components of the whole mesh (ComponentMinimum's given components).
  std::shared_ptr<const std::vector<uint32_t>> components;
  bool components_may_vanish = false;
  const std::vector<uint8_t>* on_membrane = nullptr;  // may be empty
  // The options the master's metric was made with (make_priority_module), and the whole
  // mesh's diagonal (SubsetOptions::reference_diagonal: the energy prices by it).
  const SimplifyOptions* options = nullptr;
  double reference_diagonal = 0;
  // The queue keys the pass starts from (KeyMemo::reset: current keys of live edges, sorted),
  // null for a pass without a memo; the deferred edges it queues first (first_deferred).
  const std::vector<EdgeKey>* keys = nullptr;
  const std::vector<DeferredEdge>* deferred = nullptr;
  ThreadTeam* team = nullptr;  // the master's (PriorityModule::use_team), or null
};

struct LivePass {
  std::vector<CollapseRecord> records;  // in the whole mesh's ids
  SimplifierStats stats;
  uint64_t costings = 0;
  uint64_t keys_reused = 0;  // queue costings answered from the keys carried in
  // The copy after the pass, and its ids: the whole mesh the records leave is final_mesh().
  std::unique_ptr<CollapseMesh> mesh;
  std::vector<uint32_t> vertex_in_copy;  // per vertex of the whole mesh: its id here, or kNoKey
  std::vector<uint32_t> face_in_copy;    // per face of the whole mesh: the same
  std::vector<VertexId> vertex_of_copy;  // per vertex here: its id in the whole mesh

  PartlyCopiedMesh final_mesh(const CollapseMesh& whole) const {
    return {whole, *mesh, vertex_in_copy, face_in_copy, vertex_of_copy};
  }
};

// Whether the master's metric can run its final pass on a copy: the quadric and the energy.
bool runs_on_live_copy(const PriorityModule& master);

// The standard rules' pass (standard_constraints with the inputs', seam collapses where there
// are groups) with `master`'s state and options over the live part of `whole`, to `limits`
// (but their first_deferred: the inputs'), on a compact copy; `whole` and `master` are left as
// they are (the PM is built from final_mesh()). The copy is made in `loops`' chunks. nullopt,
// and nothing run, when a live vertex holds no face (a copy holds only the faces' corners).
std::optional<LivePass> run_on_live_copy(const CollapseMesh& whole, const PriorityModule& master,
                                         const LivePassInputs& inputs,
                                         const SimplifierLimits& limits,
                                         const ProgressCallback& progress,
                                         const CancelToken* cancel, ChunkedLoops& loops);

}  // namespace parapm
