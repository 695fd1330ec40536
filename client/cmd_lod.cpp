// parapm lod IN.pm (--faces N | --error E) -o OUT.obj|OUT.ply: one level of detail.
#include <chrono>
#include <cstdio>
#include <optional>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "pm/levels.h"
#include "pm/pm_file.h"

namespace parapm::cli {
namespace {

struct LodArgs {
  std::string input;
  std::string output;
  uint64_t faces = 0;
  std::optional<double> error;  // unset: cut by --faces
  bool ascii = false;
  bool json = false;
};

int run_lod(const LodArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const ProgressiveMesh pm = read_pm_file(args.input);
  const size_t level =
      args.error ? level_for_error(pm, *args.error) : level_for_faces(pm, args.faces);
  const Mesh mesh = level_of_detail(pm, level);
  WriteOptions options;
  options.ascii = args.ascii;
  write_mesh(mesh, args.output, options);
  const double error = level < pm.splits.size() ? pm.splits[level].error : 0.0;
  const double seconds = seconds_since(start);
  spdlog::info("wrote {}: level {} of {}, {} faces, error bound {:.6g}", args.output, level,
               pm.splits.size(), mesh.face_count(), error);
  if (args.json) {
    print_json({{"output", args.output},
                {"level", level},
                {"levels", pm.splits.size()},
                {"faces", mesh.face_count()},
                {"vertices", mesh.vertex_count()},
                {"error_bound", error},
                {"bbox_diagonal", pm_bounding_box(pm).diagonal()},
                {"seconds", seconds}});
  }
  return 0;
}

}  // namespace

void add_lod_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<LodArgs>();
  CLI::App* cmd = app.add_subcommand(
      "lod",
      "Write one level of detail of a .pm: the largest with at most N faces, or the "
      "smallest whose error bound is at most E");
  cmd->add_option("input", args->input, "Input .pm")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "Output mesh (.obj or .ply, optionally .gz)")
      ->required();
  auto* faces = cmd->add_option("--faces", args->faces, "Maximum face count");
  auto* error = cmd->add_option("--error", args->error,
                                "Maximum error bound, in model units (see 'parapm info')")
                    ->check(CLI::NonNegativeNumber);
  faces->excludes(error);
  cmd->add_flag("--ascii", args->ascii, "Write ascii PLY instead of binary");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args, &exit_code, faces, error] {
    if (faces->count() == 0 && error->count() == 0) throw CLI::RequiredError("--faces or --error");
    exit_code = run_lod(*args);
  });
}

}  // namespace parapm::cli
