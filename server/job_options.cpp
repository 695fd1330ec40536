#include "job_options.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "util/error.h"
#include "util/number_text.h"

namespace parapm::service {
namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw_invalid("job options: " + message);
}

}  // namespace

uint32_t most_useful_parallelism(uint64_t faces) {
  return uint32_t(std::clamp<uint64_t>(faces / kLeastSubsetFaces, 1, kMaxParallelism));
}

JobSpec job_spec_of(const parapm::v1::JobOptions& options, uint32_t default_parallelism) {
  JobSpec spec;
  SimplifyOptions& s = spec.simplify;
  ParallelOptions& p = spec.parallel;
  switch (options.target_case()) {
    case parapm::v1::JobOptions::kTargetFaces:
      s.target_faces = options.target_faces();
      break;
    case parapm::v1::JobOptions::kTargetRatio:
      require(std::isfinite(options.target_ratio()) && options.target_ratio() > 0 &&
                  options.target_ratio() <= 1,
              "target_ratio must be in (0, 1], got " + number_text(options.target_ratio()));
      s.target_ratio = options.target_ratio();
      break;
    case parapm::v1::JobOptions::TARGET_NOT_SET:
      break;
  }
  switch (options.metric()) {
    case parapm::v1::METRIC_UNSPECIFIED:
    case parapm::v1::METRIC_QUADRIC:
      s.metric = "quadric";
      break;
    case parapm::v1::METRIC_ENERGY:
      s.metric = "energy";
      break;
    default:
      require(false, "unknown metric " + std::to_string(int(options.metric())));
  }
  switch (options.quadric_placement()) {
    case parapm::v1::QUADRIC_PLACEMENT_UNSPECIFIED:
    case parapm::v1::QUADRIC_PLACEMENT_AUTO:
      break;
    case parapm::v1::QUADRIC_PLACEMENT_CONSTRAINED:
      s.free_placement_above_faces = free_placement_above_faces_of("constrained");
      break;
    case parapm::v1::QUADRIC_PLACEMENT_FREE:
      s.free_placement_above_faces = free_placement_above_faces_of("free");
      break;
    default:
      require(false, "unknown quadric_placement " +
                         std::to_string(int(options.quadric_placement())) +
                         " (available: 1 auto, 2 constrained, 3 free)");
  }
  if (options.has_samples_per_face()) {
    require(std::isfinite(options.samples_per_face()) && options.samples_per_face() >= 0 &&
                options.samples_per_face() <= 64,
            "samples_per_face must be in [0, 64]");
    s.samples_per_face = options.samples_per_face();
  }
  if (options.has_crease_angle_degrees()) {
    require(std::isfinite(options.crease_angle_degrees()) && options.crease_angle_degrees() >= 0 &&
                options.crease_angle_degrees() <= 180,
            "crease_angle_degrees must be in [0, 180]");
    s.crease_angle_degrees = options.crease_angle_degrees();
  }
  if (options.has_attribute_weight()) s.attribute_weight = options.attribute_weight();
  const parapm::v1::EnergyTuning& e = options.energy();
  if (e.has_star_planes_weight()) s.energy.star_planes_weight = e.star_planes_weight();
  if (e.has_volume_weight()) s.energy.volume_weight = e.volume_weight();
  if (e.has_spring_scale()) s.energy.spring_scale = e.spring_scale();
  if (e.has_crease_min_length()) s.energy.crease_min_length = e.crease_min_length();
  if (e.has_min_crease_edges()) s.energy.min_crease_edges = e.min_crease_edges();
  if (options.has_seed()) s.seed = options.seed();
  s.keep_order = options.keep_order();
  s.free_copies = options.free_copies();
  s.keep_components = options.keep_components();
  check_simplify_options(s);  // the ranges of the weights and the crease rule

  p.subsets = options.has_parallelism() ? options.parallelism() : default_parallelism;
  require(p.subsets >= 1 && p.subsets <= kMaxParallelism,
          "parallelism must be in [1, 256], got " + std::to_string(p.subsets));
  if (options.has_rounds()) {
    require(options.rounds() >= 1 && options.rounds() <= 64,
            "rounds must be in [1, 64], got " + std::to_string(options.rounds()));
    p.rounds = options.rounds();
  }
  if (options.has_handover_ratio()) {
    require(std::isfinite(options.handover_ratio()) && options.handover_ratio() > 0 &&
                options.handover_ratio() <= 1,
            "handover_ratio must be in (0, 1]");
    p.handover_ratio = options.handover_ratio();
  }
  if (options.has_border_excess()) {
    require(std::isfinite(options.border_excess()) && options.border_excess() >= 0 &&
                options.border_excess() <= 0.5,
            "border_excess must be in [0, 0.5]");
    p.border_excess = options.border_excess();
  }
  auto subset_floor = [](const char* name, uint64_t value) {
    require(value == 0 || value >= kLeastSubsetFaces,
            std::string(name) + " must be 0 or at least " + std::to_string(kLeastSubsetFaces) +
                " (a smaller subset is mostly border: its rounds only cost calls)");
    return value;
  };
  if (options.has_extra_round_faces())
    p.extra_round_subset_faces = subset_floor("extra_round_faces", options.extra_round_faces());
  if (options.has_min_subset_faces())
    p.min_subset_faces = subset_floor("min_subset_faces", options.min_subset_faces());
  return spec;
}

}  // namespace parapm::service
