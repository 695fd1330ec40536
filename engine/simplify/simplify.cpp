#include "simplify/simplify.h"

#include <chrono>
#include <cmath>
#include <limits>

#include <spdlog/spdlog.h>

#include "simplify/copy_groups.h"
#include "simplify/energy_priority.h"
#include "simplify/pm_builder.h"
#include "simplify/quadric_priority.h"
#include "simplify/simplifier.h"
#include "util/clock.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/number_text.h"

namespace parapm {

uint64_t target_face_count(uint64_t input_faces, const SimplifyOptions& options) {
  if (options.target_faces != 0) return options.target_faces;
  if (options.target_ratio != 0) {
    if (!(options.target_ratio > 0 && options.target_ratio <= 1))
      throw_invalid("the target ratio must be in (0, 1], got " + number_text(options.target_ratio));
    return static_cast<uint64_t>(std::llround(options.target_ratio * double(input_faces)));
  }
  return 0;
}

const std::vector<std::string>& quadric_placements() {
  static const std::vector<std::string> names{"auto", "constrained", "free"};
  return names;
}

std::optional<uint64_t> free_placement_above_faces_of(const std::string& placement) {
  if (placement == "auto") return std::nullopt;
  if (placement == "constrained") return std::numeric_limits<uint64_t>::max();
  if (placement == "free") return 0;
  throw_invalid("unknown quadric placement '" + placement +
                "' (available: auto, constrained, free)");
}

void check_energy_tuning(const EnergyTuning& energy) {
  auto weight = [](double w, const char* what) {
    if (!(w >= 0 && w <= 1000))
      throw_invalid(std::string("the ") + what + " must be in [0, 1000], got " + number_text(w));
  };
  weight(energy.star_planes_weight, "star planes' weight");
  weight(energy.volume_weight, "volume weight");
  weight(energy.spring_scale, "spring scale");
  if (!(energy.min_crease_edges >= 1 && energy.min_crease_edges <= 1000000))
    throw_invalid("the minimum crease edges must be in [1, 1000000] (1: every crease), got " +
                  std::to_string(energy.min_crease_edges));
  if (!(energy.crease_min_length >= 0 && energy.crease_min_length <= 10))
    throw_invalid("the minimum crease length must be in [0, 10] bounding-box diagonals, got " +
                  number_text(energy.crease_min_length));
}

void check_simplify_options(const SimplifyOptions& options) {
  if (options.metric != "quadric" && options.metric != "energy")
    throw_invalid("unknown metric '" + options.metric + "' (available: quadric, energy)");
  if (!(options.crease_angle_degrees >= 0 && options.crease_angle_degrees <= 180))
    throw_invalid("the crease angle must be in [0, 180] degrees, got " +
                  number_text(options.crease_angle_degrees));
  if (!(options.attribute_weight >= 0 && options.attribute_weight <= 1000))
    throw_invalid("the attribute weight must be in [0, 1000], got " +
                  number_text(options.attribute_weight));
  if (!(options.samples_per_face >= 0 && options.samples_per_face <= 1000))
    throw_invalid("samples per face must be in [0, 1000], got " +
                  number_text(options.samples_per_face));
  check_energy_tuning(options.energy);
}

std::vector<uint8_t> locked_vertices(const RepairedMesh& repaired, bool free_copies) {
  return locked_vertices(free_copies ? CopyGroups{} : copy_groups(repaired),
                         repaired.mesh.vertex_count());
}

std::vector<uint8_t> locked_vertices(const CopyGroups& groups, size_t vertices) {
  std::vector<uint8_t> locked(vertices, 0);
  for (VertexId v : groups.members) locked[v] = 1;
  return locked;
}

std::unique_ptr<PriorityModule> make_priority_module(const SimplifyOptions& options,
                                                     const Mesh& mesh,
                                                     const std::vector<uint8_t>& locked,
                                                     double reference_diagonal) {
  if (options.metric == "energy") {
    EnergyOptions energy_options;
    energy_options.samples_per_face = options.samples_per_face;
    energy_options.seed = options.seed;
    energy_options.round_to_float = mesh.positions_are_float;
    energy_options.sharp.crease_angle_degrees = options.crease_angle_degrees;
    energy_options.sharp.min_crease_edges = options.energy.min_crease_edges;
    energy_options.sharp.long_crease_diagonals = options.energy.crease_min_length;
    energy_options.star_planes_weight = options.energy.star_planes_weight;
    energy_options.volume_weight = options.energy.volume_weight;
    energy_options.spring_scale = options.energy.spring_scale;
    energy_options.attribute_weight = options.attribute_weight;
    energy_options.reference_diagonal = reference_diagonal;
    energy_options.components_may_vanish = !options.keep_components;
    return std::make_unique<EnergyPriority>(locked, energy_options,
                                            WedgeAttributes{mesh.layout, mesh.wedge_values});
  }
  QuadricOptions quadric_options;
  quadric_options.round_to_float = mesh.positions_are_float;
  quadric_options.free_placement_above_faces = free_placement_line_of(options, mesh.face_count());
  return std::make_unique<QuadricPriority>(locked, quadric_options);
}

ProgressiveMesh build_progressive_mesh(const RepairedMesh& repaired, const SimplifyOptions& options,
                                       SimplifyStats* stats, const ProgressCallback& progress,
                                       const CancelToken* cancel) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_seconds();
  check_simplify_options(options);
  const Mesh& mesh = repaired.mesh;

  // Vertices the repair step duplicated (non-manifold input) stay where they are, so that the
  // copies of one input vertex never drift apart and open a crack (unless free_copies); they
  // leave the mesh group by group (seam collapses), the sheets meeting still.
  std::vector<uint8_t> on_membrane = membrane_vertices(repaired);
  const CopyGroups groups = options.free_copies ? CopyGroups{} : copy_groups(repaired, on_membrane);
  const std::vector<uint8_t> locked = locked_vertices(groups, mesh.vertex_count());
  CollapseMesh working(mesh);
  std::unique_ptr<PriorityModule> priority = make_priority_module(options, mesh, locked);
  Simplifier simplifier(
      working, *priority,
      standard_constraints(locked, {}, !options.keep_components, std::move(on_membrane)));
  if (!groups.empty()) simplifier.join_copies(&groups);
  SimplifierLimits limits;
  limits.target_faces = target_face_count(mesh.face_count(), options);
  if (options.defer_recosting) limits.defer_above_faces = defer_recosting_line(mesh.face_count());
  const auto records = simplifier.run(limits, progress, cancel);
  release_free_memory();  // what the run freed (its queue's ranges), before the PM's arrays

  PmBuildOptions build_options;
  build_options.keep_order = options.keep_order;
  ProgressiveMesh pm = build_pm_from_collapses(repaired, working, records, build_options);
  pm.info.metric = priority->name();
  const double seconds = seconds_since(start);
  pm.info.seconds = seconds;
  if (stats) {
    stats->collapses = simplifier.stats().collapses;
    stats->rejected = simplifier.stats().rejected;
    stats->stop_reason = simplifier.stats().stop_reason;
    stats->seconds = seconds;
    stats->costings = priority->costings();
    stats->cpu_seconds = thread_cpu_seconds() - cpu_start;
  }
  spdlog::debug(
      "simplified {} -> {} faces in {:.3f} s ({} collapses, {} vetoed ({} as queued), {} "
      "screened, {} evaluations, {} deferred, {} requeued, {} seam collapses ({} split); {})",
      mesh.face_count(), pm.base.face_count(), seconds, simplifier.stats().collapses,
      simplifier.stats().rejected, simplifier.stats().vetoed_when_queued,
      simplifier.stats().screened, simplifier.stats().evaluations, simplifier.stats().deferred,
      simplifier.stats().requeued, simplifier.stats().seam_collapses,
      simplifier.stats().seams_split, simplifier.stats().stop_reason);
  return pm;
}

}  // namespace parapm
