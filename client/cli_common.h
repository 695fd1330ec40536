// What every parapm subcommand shares: the progress bar, the load-and-repair step with its
// report, and the convention that --json prints exactly one JSON object on stdout.
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "util/clock.h"
#include "util/progress.h"

namespace parapm::cli {

// Draws "label [=====>    ] 45%" on stderr when stderr is a terminal; silent otherwise.
class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  ~ProgressBar();
  ProgressCallback callback();
  void finish();

 private:
  void draw(uint64_t done, uint64_t total);
  std::string label_;
  bool enabled_;
  int last_permille_ = -1;
  bool finished_ = false;
};

struct LoadedMesh {
  ReadReport read;
  uint64_t input_vertices = 0;
  uint64_t input_faces = 0;
  double read_seconds = 0;
  double repair_seconds = 0;
  // Reading and repair with a core per chunk of RepairOptions::loops (the seconds above
  // without them).
  double read_critical_seconds = 0;
  double repair_critical_seconds = 0;
  RepairedMesh repaired;
};

// Reads and repairs (both in RepairOptions::loops' chunks when given); logs one info line with
// what was repaired.
LoadedMesh load_and_repair(const std::string& path, const RepairOptions& options);

nlohmann::json repair_report_json(const RepairReport& report);

// Prints a JSON object on stdout, one line.
void print_json(const nlohmann::json& object);

}  // namespace parapm::cli
