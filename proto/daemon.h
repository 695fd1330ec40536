// What both daemons share around their servers: the program's named logger, and a clean stop
// on SIGINT / SIGTERM (the server drains its calls, up to a grace period, then exits 0).
#pragma once

#include <chrono>
#include <string>

#include <grpcpp/grpcpp.h>

namespace parapm::rpc {

// Makes a logger named `program` the default (the engine's lines go there too), at `level`
// ("trace", "debug", "info", "warn", "error", "off"), writing to stderr in `format`: "text"
// (a line of time, program, level, message) or "json" (one object per line, for log
// collectors: time in UTC, level, logger, message). Throws Error(kInvalidInput) for an
// unknown level or format.
void set_up_logging(const std::string& program, const std::string& level,
                    const std::string& format = "text");

// The token of a daemon listening on `listen` (rpc::load_token of `token_file`). Throws
// Error(kInvalidInput) when there is none and `listen` reaches beyond loopback: every call
// from the network must carry one.
std::string token_for_listening(const std::string& token_file, const std::string& listen);

// Blocks SIGINT and SIGTERM in the calling thread and every thread it starts afterwards:
// call first thing in main().
void block_shutdown_signals();

// Waits for SIGINT or SIGTERM; returns the signal's name.
std::string wait_for_shutdown_signal();

}  // namespace parapm::rpc
