// parapm check IN.pm --against ORIGINAL: exit 0 iff applying every vertex split of the PM
// gives back the original (after the documented repairs) exactly.
#include <cstdio>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "mesh/repaired_input.h"
#include "pm/pm_file.h"
#include "pm/pm_restore.h"

namespace parapm::cli {
namespace {

struct CheckArgs {
  std::string input;
  std::string original;
  bool json = false;
};

int run_check(const CheckArgs& args) {
  const ProgressiveMesh pm = read_pm_file(args.input);
  const bool same_numbering = !pm.input_vertex_order.empty();
  RepairOptions repair_options;
  repair_options.keep_unreferenced = same_numbering;
  const LoadedMesh loaded = load_and_repair(args.original, repair_options);
  const Mesh expected = repaired_input(loaded.repaired);
  const Mesh restored = restore_input(pm);
  const MeshDifference difference = compare_meshes_exact(restored, expected, same_numbering);
  if (args.json) {
    print_json({{"equal", difference.equal},
                {"same_numbering", same_numbering},
                {"difference", difference.first_difference},
                {"vertices", restored.vertex_count()},
                {"faces", restored.face_count()}});
  } else if (difference.equal) {
    std::printf("OK: %s rebuilds %s exactly (%zu vertices, %zu faces%s)\n", args.input.c_str(),
                args.original.c_str(), restored.vertex_count(), restored.face_count(),
                same_numbering ? ", same numbering" : ", up to vertex renumbering");
  } else {
    std::printf("DIFFERENT: %s\n", difference.first_difference.c_str());
  }
  return difference.equal ? 0 : 1;
}

}  // namespace

void add_check_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App* cmd = app.add_subcommand(
      "check",
      "Exit 0 iff the PM rebuilds the original mesh exactly (positions bit for bit, "
      "attributes, faces and their orientation; up to vertex renumbering unless the "
      "PM was built with --keep-order); exit 1 and name the first difference otherwise");
  cmd->add_option("input", args->input, "The .pm")->required()->check(CLI::ExistingFile);
  cmd->add_option("--against", args->original, "The original mesh file")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args, &exit_code] { exit_code = run_check(*args); });
}

}  // namespace parapm::cli
