// The energy's tuning as build options (SimplifyOptions::energy, simplify.h): each knob reaches
// the metric, and values out of range are errors that name the knob.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <string>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "parallel/subset_job.h"
#include "pm/pm_file.h"
#include "simplify/energy_priority.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm {
namespace {

// The textured bunny (a scan: short noise creases, which the crease knobs decide about once
// creases are on) to 10%, with one knob changed from its default: a different PM for every
// knob, and the same bytes again with the defaults spelled out.
TEST(EnergyTuning, EveryKnobReachesTheMetric) {
  const RepairedMesh repaired =
      repair_mesh(read_mesh(testing::test_data("pymeshlab-bunny-textured-10k.obj")));
  SimplifyOptions options;
  options.metric = "energy";
  options.target_ratio = 0.1;
  options.crease_angle_degrees = 60;  // creases on (off by default), for the crease knobs
  const std::string defaults = testing::pm_bytes(build_progressive_mesh(repaired, options));
  SimplifyOptions spelled = options;
  spelled.energy = EnergyTuning{30, 64, 0.03, 8, 0.05};
  EXPECT_EQ(testing::pm_bytes(build_progressive_mesh(repaired, spelled)), defaults);

  const std::vector<std::pair<const char*, std::function<void(EnergyTuning&)>>> knobs = {
      {"star planes' weight", [](EnergyTuning& e) { e.star_planes_weight = 0; }},
      {"volume weight", [](EnergyTuning& e) { e.volume_weight = 0; }},
      {"spring scale", [](EnergyTuning& e) { e.spring_scale = 1; }},
      {"minimum crease edges", [](EnergyTuning& e) { e.min_crease_edges = 1; }},
      {"minimum crease length", [](EnergyTuning& e) { e.crease_min_length = 0; }}};
  for (const auto& [name, change] : knobs) {
    SimplifyOptions changed = options;
    change(changed.energy);
    EXPECT_NE(testing::pm_bytes(build_progressive_mesh(repaired, changed)), defaults) << name;
  }
}

// The build options' defaults are the metric's own (two places hold them: the options a user
// sees, and the module's, which its header explains).
TEST(EnergyTuning, DefaultsAreTheMetricsDefaults) {
  const EnergyTuning tuning;
  const EnergyOptions energy;
  EXPECT_EQ(tuning.star_planes_weight, energy.star_planes_weight);
  EXPECT_EQ(tuning.volume_weight, energy.volume_weight);
  EXPECT_EQ(tuning.spring_scale, energy.spring_scale);
  EXPECT_EQ(tuning.min_crease_edges, energy.sharp.min_crease_edges);
  EXPECT_EQ(SimplifyOptions{}.crease_angle_degrees, energy.sharp.crease_angle_degrees);
  EXPECT_EQ(SubsetOptions{}.crease_angle_degrees, energy.sharp.crease_angle_degrees);
  EXPECT_EQ(tuning.crease_min_length, energy.sharp.long_crease_diagonals);
}

TEST(EnergyTuning, ValuesOutOfRangeAreErrorsNamingTheKnob) {
  const std::vector<std::pair<const char*, std::function<void(EnergyTuning&)>>> bad = {
      {"star planes' weight", [](EnergyTuning& e) { e.star_planes_weight = -1; }},
      {"volume weight", [](EnergyTuning& e) { e.volume_weight = 1e6; }},
      {"spring scale", [](EnergyTuning& e) { e.spring_scale = std::nan(""); }},
      {"minimum crease edges", [](EnergyTuning& e) { e.min_crease_edges = 0; }},
      {"minimum crease length", [](EnergyTuning& e) { e.crease_min_length = 11; }}};
  for (const auto& [name, change] : bad) {
    SimplifyOptions options;
    options.metric = "energy";
    change(options.energy);
    testing::expect_error([&] { check_simplify_options(options); }, ErrorCode::kInvalidInput,
                          {name});
  }
}

}  // namespace
}  // namespace parapm
