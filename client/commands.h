// The subcommands of parapm. Each add_* registers its options on the app and the function
// that runs it; the function returns the process exit code.
#pragma once

#include <CLI/CLI.hpp>

namespace parapm::cli {

void add_simplify_command(CLI::App& app, int& exit_code);
void add_lod_command(CLI::App& app, int& exit_code);
void add_info_command(CLI::App& app, int& exit_code);
void add_check_command(CLI::App& app, int& exit_code);
void add_partition_command(CLI::App& app, int& exit_code);

}  // namespace parapm::cli
