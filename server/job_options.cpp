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
  require(std::isfinite(options.samples_per_face()) && options.samples_per_face() >= 0 &&
              options.samples_per_face() <= 64,
          "samples_per_face must be in [0, 64]");
  s.samples_per_face = options.samples_per_face();
  require(std::isfinite(options.crease_angle_degrees()) && options.crease_angle_degrees() >= 0 &&
              options.crease_angle_degrees() <= 180,
          "crease_angle_degrees must be in [0, 180] (0: 60)");
  if (options.crease_angle_degrees() > 0) s.crease_angle_degrees = options.crease_angle_degrees();
  require(std::isfinite(options.attribute_weight()), "attribute_weight must be finite");
  if (options.attribute_weight() < 0)
    s.attribute_weight = 0;
  else if (options.attribute_weight() > 0)
    s.attribute_weight = options.attribute_weight();
  const parapm::v1::EnergyTuning& e = options.energy();
  auto tuning = [&](double value, double& out, const char* name) {
    require(std::isfinite(value), std::string("energy.") + name + " must be finite");
    if (value < 0) out = 0;
    if (value > 0) out = value;
  };
  tuning(e.star_planes_weight(), s.energy.star_planes_weight, "star_planes_weight");
  tuning(e.volume_weight(), s.energy.volume_weight, "volume_weight");
  tuning(e.spring_scale(), s.energy.spring_scale, "spring_scale");
  tuning(e.crease_min_length(), s.energy.crease_min_length, "crease_min_length");
  if (e.min_crease_edges() > 0) s.energy.min_crease_edges = e.min_crease_edges();
  s.seed = options.seed() ? options.seed() : 1;
  s.keep_order = options.keep_order();
  s.free_copies = options.free_copies();
  check_simplify_options(s);

  p.subsets = options.parallelism() ? options.parallelism() : default_parallelism;
  require(p.subsets >= 1 && p.subsets <= kMaxParallelism,
          "parallelism must be in [1, 256], got " + std::to_string(p.subsets));
  p.rounds = options.rounds();  // 0 in both: by p
  require(p.rounds <= 64, "rounds must be in [1, 64] (0: by p), got " + std::to_string(p.rounds));
  if (options.handover_ratio() != 0) p.handover_ratio = options.handover_ratio();
  require(std::isfinite(p.handover_ratio) && p.handover_ratio > 0 && p.handover_ratio <= 1,
          "handover_ratio must be in (0, 1]");
  require(std::isfinite(options.border_excess()) && options.border_excess() <= 0.5,
          "border_excess must be at most 0.5 (0: the default, 0.05; negative: none)");
  if (options.border_excess() < 0) p.border_excess = 0;
  if (options.border_excess() > 0) p.border_excess = options.border_excess();
  require(options.extra_round_faces() <= 0 ||
              uint64_t(options.extra_round_faces()) >= kLeastSubsetFaces,
          "extra_round_faces must be at least " + std::to_string(kLeastSubsetFaces) +
              " (a smaller subset is mostly border: its rounds only cost calls; 0: the default, "
              "negative: no extra rounds)");
  require(
      options.min_subset_faces() <= 0 || uint64_t(options.min_subset_faces()) >= kLeastSubsetFaces,
      "min_subset_faces must be at least " + std::to_string(kLeastSubsetFaces) +
          " (a smaller subset is mostly border: its rounds only cost calls; 0: the metric's "
          "default, negative: no floor)");
  if (options.extra_round_faces() < 0) p.extra_round_subset_faces = 0;
  if (options.extra_round_faces() > 0)
    p.extra_round_subset_faces = uint64_t(options.extra_round_faces());
  if (options.min_subset_faces() < 0) p.min_subset_faces = 0;
  if (options.min_subset_faces() > 0) p.min_subset_faces = uint64_t(options.min_subset_faces());
  return spec;
}

}  // namespace parapm::service
