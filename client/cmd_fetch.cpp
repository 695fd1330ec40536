// parapm get JOB -o OUT.pm / parapm level JOB (--faces N | --error E) -o OUT.obj|ply: fetch a
// finished job's Progressive Mesh, or one level of detail cut from it by the coordinator.
#include <optional>

#include "cli_common.h"
#include "commands.h"
#include "service_client.h"
#include "util/error.h"

namespace parapm::cli {
namespace {

struct FetchArgs {
  ConnectionArgs connection;
  std::string job_id;
  std::string output;
  uint64_t faces = 0;
  std::optional<double> error;  // unset: cut by --faces
  bool json = false;
};

int run_get(const FetchArgs& args) {
  ServiceClient client(args.connection);
  const uint64_t bytes = client.download(args.job_id, args.output);
  if (args.json)
    print_json({{"job_id", args.job_id}, {"path", args.output}, {"bytes", bytes}});
  else
    std::printf("wrote %s (%llu bytes)\n", args.output.c_str(), (unsigned long long)bytes);
  return 0;
}

int run_level(const FetchArgs& args) {
  const std::filesystem::path out(args.output);
  const std::string ext = out.extension().string();
  if (ext != ".obj" && ext != ".ply")
    throw_invalid(args.output + ": the output must be .obj or .ply");
  ServiceClient client(args.connection);
  parapm::v1::LevelRequest request;
  request.set_job_id(args.job_id);
  if (args.error)
    request.set_max_error(*args.error);
  else
    request.set_max_faces(args.faces);
  request.set_format(ext.substr(1));
  auto context = client.context(0);
  auto reader = client.stub().GetLevel(context.get(), request);
  const uint64_t bytes = client.receive_file(*reader, out, "level of " + args.job_id);
  if (args.json)
    print_json({{"job_id", args.job_id}, {"path", args.output}, {"bytes", bytes}});
  else
    std::printf("wrote %s (%llu bytes)\n", args.output.c_str(), (unsigned long long)bytes);
  return 0;
}

}  // namespace

void add_fetch_commands(CLI::App& app, int& exit_code) {
  auto get = std::make_shared<FetchArgs>();
  CLI::App* g = app.add_subcommand("get", "download a finished job's .pm");
  g->add_option("job", get->job_id, "job id")->required();
  g->add_option("-o,--output", get->output, "the .pm to write")->required();
  g->add_flag("--json", get->json, "print {job_id, path, bytes}");
  add_connection_options(g, get->connection);
  g->callback([get, &exit_code] { exit_code = run_get(*get); });

  auto level = std::make_shared<FetchArgs>();
  CLI::App* l = app.add_subcommand(
      "level",
      "fetch one level of detail of a finished job: the largest with at most N faces, "
      "or the coarsest within error E");
  l->add_option("job", level->job_id, "job id")->required();
  auto* faces = l->add_option("--faces", level->faces, "at most this many faces");
  auto* error = l->add_option("--error", level->error, "geometric error bound, model units")
                    ->check(CLI::NonNegativeNumber);
  faces->excludes(error);
  l->add_option("-o,--output", level->output, "OUT.obj or OUT.ply")->required();
  l->add_flag("--json", level->json, "print {job_id, path, bytes}");
  add_connection_options(l, level->connection);
  l->callback([level, faces, error, &exit_code] {
    if (faces->count() == 0 && error->count() == 0) throw_invalid("level: give --faces or --error");
    exit_code = run_level(*level);
  });
}

}  // namespace parapm::cli
