// parapm lod IN.pm (--faces N | --error E) -o OUT.obj|.ply|.glb|.gltf: one level of detail.
// parapm lods IN.pm (--faces N1,N2,... | --errors E1,E2,...) -o OUT.glb|.gltf: a chain of
// levels in one glTF file (MSFT_lod).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "io/gltf_writer.h"
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
  const double error = level < pm.splits.size() ? pm.splits[level].error : 0.0;
  if (is_gltf_path(args.output)) {
    write_gltf({{&mesh, level, error}}, args.output);
  } else {
    WriteOptions options;
    options.ascii = args.ascii;
    write_mesh(mesh, args.output, options);
  }
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

struct LodsArgs {
  std::string input;
  std::string output;
  std::vector<uint64_t> faces;
  std::vector<double> errors;
  bool json = false;
};

int run_lods(const LodsArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const ProgressiveMesh pm = read_pm_file(args.input);
  // The levels asked for, finest first, each once.
  std::vector<size_t> levels;
  for (uint64_t faces : args.faces) levels.push_back(level_for_faces(pm, faces));
  for (double error : args.errors) levels.push_back(level_for_error(pm, error));
  std::sort(levels.rbegin(), levels.rend());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  std::vector<Mesh> meshes;
  meshes.reserve(levels.size());
  std::vector<GltfLevel> chain;
  for (size_t level : levels) {
    meshes.push_back(level_of_detail(pm, level));
    chain.push_back(
        {&meshes.back(), level, level < pm.splits.size() ? pm.splits[level].error : 0.0});
  }
  write_gltf(chain, args.output);
  spdlog::info("wrote {}: {} levels, {} to {} faces", args.output, chain.size(),
               chain.front().mesh->face_count(), chain.back().mesh->face_count());
  if (args.json) {
    nlohmann::json written = nlohmann::json::array();
    for (const GltfLevel& level : chain)
      written.push_back({{"level", level.level},
                         {"faces", level.mesh->face_count()},
                         {"vertices", level.mesh->vertex_count()},
                         {"error_bound", level.error_bound}});
    print_json({{"output", args.output},
                {"levels", written},
                {"bbox_diagonal", pm_bounding_box(pm).diagonal()},
                {"seconds", seconds_since(start)}});
  }
  return 0;
}

}  // namespace

void add_lods_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<LodsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "lods",
      "Write a chain of levels of detail of a .pm into one glTF file (MSFT_lod: the finest "
      "level's node names the coarser ones; each level's error bound in its node's extras)");
  cmd->add_option("input", args->input, "Input .pm")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "Output glTF (.glb binary, or .gltf JSON)")
      ->required()
      ->check([](const std::string& path) {
        return is_gltf_path(path) ? std::string() : "the output is a .glb or .gltf file";
      });
  auto* faces = cmd->add_option("--faces", args->faces,
                                "Levels by maximum face count, comma separated (e.g. "
                                "100000,20000,4000)")
                    ->delimiter(',');
  auto* errors = cmd->add_option("--errors", args->errors,
                                 "Levels by maximum error bound in model units, comma separated")
                     ->delimiter(',')
                     ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args, &exit_code, faces, errors] {
    if (faces->count() == 0 && errors->count() == 0)
      throw CLI::RequiredError("--faces or --errors");
    exit_code = run_lods(*args);
  });
}

void add_lod_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<LodArgs>();
  CLI::App* cmd = app.add_subcommand(
      "lod",
      "Write one level of detail of a .pm: the largest with at most N faces, or the "
      "smallest whose error bound is at most E");
  cmd->add_option("input", args->input, "Input .pm")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output,
                  "Output mesh: .obj or .ply (optionally .gz), or glTF: .glb or .gltf")
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
