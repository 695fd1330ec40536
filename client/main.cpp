// parapm: the command-line tool. Local commands work on files in-process; the service
// commands (up, submit, jobs, watch, get, level, stream, cancel) talk to a coordinator.
#include <CLI/CLI.hpp>
#include <cstdio>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "util/error.h"

int main(int argc, char** argv) {
  auto logger = spdlog::stderr_color_mt("parapm");
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("%^[%L]%$ %v");

  CLI::App app{
      "parapm: builds Progressive Meshes (a base mesh plus vertex splits) from triangle meshes, "
      "and cuts them into levels of detail, in-process or through a ParaPM coordinator.\n"
      "Exit status: 0 success, 1 'check' found a difference or a job failed or was cancelled, "
      "2 an error (one line on stderr), 3 the coordinator could not be reached."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "parapm 0.1.0");
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  int exit_code = 0;
  parapm::cli::add_simplify_command(app, exit_code);
  parapm::cli::add_lod_command(app, exit_code);
  parapm::cli::add_lods_command(app, exit_code);
  parapm::cli::add_info_command(app, exit_code);
  parapm::cli::add_check_command(app, exit_code);
  parapm::cli::add_partition_command(app, exit_code);
#ifdef PARAPM_WITH_SERVICE
  parapm::cli::add_up_command(app, exit_code);
  parapm::cli::add_submit_command(app, exit_code);
  parapm::cli::add_jobs_commands(app, exit_code);
  parapm::cli::add_fetch_commands(app, exit_code);
  parapm::cli::add_stream_command(app, exit_code);
  parapm::cli::add_view_command(app, exit_code);
#endif
  app.parse_complete_callback([&] { spdlog::set_level(spdlog::level::from_str(log_level)); });

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const parapm::Error& e) {
    std::fprintf(stderr, "parapm: %s\n", e.what());
    return e.code() == parapm::ErrorCode::kIo &&
                   std::string(e.what()).find("UNAVAILABLE") != std::string::npos
               ? 3
               : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "parapm: internal error: %s\n", e.what());
    return 2;
  }
  return exit_code;
}
