// The subcommands of parapm. Each add_* registers its options on the app and the function
// that runs it; the function returns the process exit code.
#pragma once

#include <CLI/CLI.hpp>

namespace parapm::cli {

void add_simplify_command(CLI::App& app, int& exit_code);
void add_lod_command(CLI::App& app, int& exit_code);
void add_lods_command(CLI::App& app, int& exit_code);
void add_info_command(CLI::App& app, int& exit_code);
void add_check_command(CLI::App& app, int& exit_code);
void add_partition_command(CLI::App& app, int& exit_code);
// The service commands (service_client.h), when built with the service.
void add_up_command(CLI::App& app, int& exit_code);
void add_submit_command(CLI::App& app, int& exit_code);
void add_jobs_commands(CLI::App& app, int& exit_code);   // jobs, watch, cancel, delete
void add_fetch_commands(CLI::App& app, int& exit_code);  // get, level
void add_stream_command(CLI::App& app, int& exit_code);
void add_view_command(CLI::App& app, int& exit_code);

}  // namespace parapm::cli
