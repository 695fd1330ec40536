// What the service commands (submit, jobs, watch, get, level, stream, cancel) share: the
// library's client (<parapm/client.h>: the connection, a chunked upload, watching a job to its
// end, a download) and the connection options on the command line (--server, --token-file,
// --tls, --tls-ca).
#pragma once

#include <parapm/client.h>
#include <CLI/CLI.hpp>

namespace parapm::cli {

using ConnectionArgs = client::ConnectionOptions;
using client::check_status;
using client::describe_event;
using client::job_state_name;
using client::kDefaultServer;
using client::kDefaultViewer;
using client::ServiceClient;

void add_connection_options(CLI::App* command, ConnectionArgs& args);

}  // namespace parapm::cli
