// parapm info IN.pm: what a .pm holds.
#include <cstdio>

#include "cli_common.h"
#include "commands.h"
#include "pm/pm_file.h"
#include "pm/pm_format.h"
#include "pm/pm_restore.h"

namespace parapm::cli {
namespace {

struct InfoArgs {
  std::string input;
  bool json = false;
};

int run_info(const InfoArgs& args) {
  const ProgressiveMesh pm = read_pm_file(args.input);
  const Box box = pm_bounding_box(pm);  // of every position at every level
  const uint64_t pm_bytes = std::filesystem::file_size(args.input);
  const uint64_t ply_bytes = binary_ply_size(restore_input(pm));
  const double coarsest_error = pm.splits.empty() ? 0.0 : pm.splits.front().error;
  const AttributeLayout& layout = pm.base.layout;
  nlohmann::json attributes = nlohmann::json::array();
  if (layout.normals) attributes.push_back("normals");
  if (layout.texcoords) attributes.push_back("texcoords");
  if (layout.colors) attributes.push_back("colors");
  const nlohmann::json info = {
      {"file", args.input},
      {"format_version", pm_format::kVersion},
      {"metric", pm.info.metric},
      {"positions", pm.base.positions_are_float ? "float32" : "float64"},
      {"attributes", attributes},
      {"base_vertices", pm.base.vertex_count()},
      {"base_faces", pm.base.face_count()},
      {"base_wedges", pm.base.wedge_count()},
      {"vsplits", pm.splits.size()},
      {"full_vertices", pm.full_vertex_count()},
      {"full_faces", pm.full_face_count()},
      {"full_wedges", pm.full_wedge_count()},
      {"vertex_copies", pm.vertex_copies.size()},
      {"keeps_input_order", !pm.input_vertex_order.empty()},
      {"input_vertices", pm.info.input_vertices},
      {"input_faces", pm.info.input_faces},
      {"base_error_bound", coarsest_error},
      {"bbox_diagonal", box.diagonal()},
      {"bbox_min", {box.min[0], box.min[1], box.min[2]}},
      {"bbox_max", {box.max[0], box.max[1], box.max[2]}},
      {"pm_bytes", pm_bytes},
      {"binary_ply_bytes", ply_bytes},
      {"pm_to_ply_ratio", ply_bytes ? double(pm_bytes) / double(ply_bytes) : 0.0}};
  if (args.json) {
    print_json(info);
  } else {
    for (const auto& [key, value] : info.items())
      std::printf("%-20s %s\n", key.c_str(), value.dump().c_str());
  }
  return 0;
}

}  // namespace

void add_info_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<InfoArgs>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a .pm file: header fields and sizes");
  cmd->add_option("input", args->input, "Input .pm")->required()->check(CLI::ExistingFile);
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args, &exit_code] { exit_code = run_info(*args); });
}

}  // namespace parapm::cli
