#include "simplify/simplify.h"

#include <chrono>
#include <cmath>

#include <spdlog/spdlog.h>

#include "simplify/pm_builder.h"
#include "simplify/quadric_priority.h"
#include "simplify/simplifier.h"
#include "util/error.h"

namespace parapm {

uint64_t target_face_count(uint64_t input_faces, const SimplifyOptions& options) {
  if (options.target_faces != 0) return options.target_faces;
  if (options.target_ratio != 0) {
    if (!(options.target_ratio > 0 && options.target_ratio <= 1))
      throw_invalid("the target ratio must be in (0, 1], got " +
                    std::to_string(options.target_ratio));
    return static_cast<uint64_t>(std::llround(options.target_ratio * double(input_faces)));
  }
  return 0;
}

ProgressiveMesh build_progressive_mesh(const RepairedMesh& repaired, const SimplifyOptions& options,
                                       SimplifyStats* stats, const ProgressCallback& progress,
                                       const CancelToken* cancel) {
  const auto start = std::chrono::steady_clock::now();
  if (options.metric != "quadric")
    throw_invalid("unknown metric '" + options.metric + "' (available: quadric)");
  const Mesh& mesh = repaired.mesh;

  // Vertices the repair step duplicated (non-manifold input) stay where they are, so that the
  // copies of one input vertex never drift apart and open a crack.
  std::vector<uint8_t> locked(mesh.vertex_count(), 0);
  {
    std::vector<uint32_t> uses(repaired.input_vertex.empty() ? 0 : mesh.vertex_count(), 0);
    for (VertexId in : repaired.input_vertex) {
      if (in >= uses.size()) uses.resize(size_t(in) + 1, 0);
      ++uses[in];
    }
    for (VertexId v = 0; v < mesh.vertex_count(); ++v)
      if (!repaired.input_vertex.empty() && uses[repaired.input_vertex[v]] > 1) locked[v] = 1;
  }

  CollapseMesh working(mesh);
  QuadricOptions quadric_options;
  quadric_options.round_to_float = mesh.positions_are_float;
  QuadricPriority priority(locked, quadric_options);
  Simplifier simplifier(working, priority, standard_constraints(locked));
  SimplifierLimits limits;
  limits.target_faces = target_face_count(mesh.face_count(), options);
  const auto records = simplifier.run(limits, progress, cancel);

  PmBuildOptions build_options;
  build_options.keep_order = options.keep_order;
  ProgressiveMesh pm = build_pm_from_collapses(repaired, working, records, build_options);
  pm.info.metric = priority.name();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  pm.info.seconds = seconds;
  if (stats) {
    stats->collapses = simplifier.stats().collapses;
    stats->rejected = simplifier.stats().rejected;
    stats->stop_reason = simplifier.stats().stop_reason;
    stats->seconds = seconds;
  }
  spdlog::debug("simplified {} -> {} faces in {:.3f} s ({} collapses, {} vetoed; {})",
                mesh.face_count(), pm.base.face_count(), seconds, simplifier.stats().collapses,
                simplifier.stats().rejected, simplifier.stats().stop_reason);
  return pm;
}

}  // namespace parapm
