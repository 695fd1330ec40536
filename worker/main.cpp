// parapm-worker: a worker daemon. It serves WorkerService (subset jobs from the coordinator,
// run with the engine's simplify_subset) and registers with the coordinator, beating at the
// interval the coordinator asks for. With --metrics-listen, serves its Prometheus metrics.
// Stops cleanly on SIGINT / SIGTERM.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <thread>

#include <spdlog/spdlog.h>

#include "coordinator_link.h"
#include "daemon.h"
#include "held_state_cache.h"
#include "metrics.h"
#include "rpc_server.h"
#include "subset_service.h"
#include "util/memory.h"
#include "worker_metrics.h"

namespace {

struct WorkerArgs {
  std::string coordinator = "127.0.0.1:50051";
  std::string listen = "127.0.0.1:0";
  std::string advertise;
  unsigned threads = 0;
  double capacity = 1;
  std::string name;
  std::string token_file;
  parapm::rpc::TlsFiles tls;
  bool coordinator_tls = false;
  std::string metrics_listen;  // "" : no metrics endpoint
  uint64_t held_state_mb = 1024;
  std::string log_level = "info";
  std::string log_format = "text";
};

int run(const WorkerArgs& args) {
  using namespace parapm;
  rpc::set_up_logging("worker", args.log_level, args.log_format);
  const std::string token = rpc::token_for_listening(args.token_file, args.listen);
  const unsigned threads = args.threads ? args.threads : std::thread::hardware_concurrency();
  worker::WorkerMetrics metrics(threads);
  // A build's held state goes unused between its rounds for seconds; ten minutes unused, the
  // build is over or gone.
  worker::HeldStateCache held(args.held_state_mb << 20, std::chrono::minutes(10));
  worker::SubsetService service(rpc::TokenCheck(token), threads, metrics, held);
  // The metrics endpoint's options are checked before anything listens.
  std::optional<rpc::MetricsServer> metrics_server;
  if (!args.metrics_listen.empty())
    metrics_server.emplace(metrics.registry,
                           rpc::MetricsEndpoint{args.metrics_listen, token, args.tls}, [&] {
                             metrics.running.Set(double(service.running()));
                             metrics.held_state_bytes.Set(double(held.bytes()));
                           });
  rpc::ServerSetup setup;
  setup.listen = args.listen;
  setup.tls = args.tls;
  rpc::StartedServer server = rpc::start_server(setup, {&service});
  const std::string address =
      args.advertise.empty() ? rpc::reachable_address(args.listen, server.port) : args.advertise;
  spdlog::info("listening on {} ({} subset slots); coordinator {}", address, threads,
               args.coordinator);
  if (metrics_server) metrics_server->start();

  worker::LinkOptions link;
  link.coordinator = args.coordinator;
  link.credentials = rpc::channel_credentials(args.coordinator_tls, args.tls);
  link.token = token;
  link.info.set_address(address);
  link.info.set_threads(threads);
  link.info.set_capacity(args.capacity);
  link.info.set_name(args.name.empty() ? address : args.name);
  {
    worker::CoordinatorLink coordinator(link, [&] { return service.running(); });
    const std::string signal = rpc::wait_for_shutdown_signal();
    spdlog::info("{}: stopping (running subsets are cancelled)", signal);
  }
  if (metrics_server) metrics_server->stop();
  // Calls in flight see their context cancelled; the engine stops at its next check.
  server.server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  spdlog::info("stopped");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  parapm::rpc::block_shutdown_signals();
  parapm::map_large_blocks_alone();  // jobs run on pools of threads
  WorkerArgs args;
  CLI::App app{
      "parapm-worker: simplifies subsets of meshes for a ParaPM coordinator. It listens for the "
      "coordinator's calls, registers with it and beats; start as many as you have machines "
      "(or cores)."};
  app.add_option("--coordinator", args.coordinator, "the coordinator's address host:port")
      ->capture_default_str();
  app.add_option("--listen", args.listen,
                 "where to listen for the coordinator's calls (port 0: any free port)")
      ->capture_default_str();
  app.add_option("--advertise", args.advertise,
                 "the address the coordinator should call (default: the listening address; "
                 "set it behind NAT or in a container)");
  app.add_option(
         "--threads", args.threads,
         "subsets run at once (0: one per hardware thread); a subset started while slots are "
         "idle shares them for its energy point projections")
      ->capture_default_str();
  app.add_option("--capacity", args.capacity,
                 "relative speed of this machine; the coordinator gives faster workers more work")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--held-state-mb", args.held_state_mb,
                 "memory for the state kept between a build's rounds, so that later jobs need "
                 "not carry it (a quadric build's quadrics, about 128 bytes a vertex; an energy "
                 "build's sample points, about 41 bytes a point; the builds used longest ago "
                 "are dropped past it, and their next jobs come whole)")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t{0}, uint64_t{1} << 20));
  app.add_option("--name", args.name, "name in the coordinator's events and logs");
  app.add_option("--token-file", args.token_file,
                 "bearer token for every call, both ways (else PARAPM_TOKEN; required when "
                 "listening beyond loopback)");
  app.add_option("--tls-cert", args.tls.cert_file, "PEM certificate: serve over TLS");
  app.add_option("--tls-key", args.tls.key_file, "PEM private key of --tls-cert");
  app.add_flag("--coordinator-tls", args.coordinator_tls, "reach the coordinator over TLS");
  app.add_option("--tls-ca", args.tls.ca_file,
                 "PEM roots that sign the coordinator's certificate (default: the system's)");
  app.add_option("--metrics-listen", args.metrics_listen,
                 "serve Prometheus metrics at http://ADDR/metrics, host:port (beyond loopback "
                 "the token is required as Authorization: Bearer TOKEN; HTTPS with --tls-cert)");
  app.add_option("--log-level", args.log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  app.add_option("--log-format", args.log_format,
                 "text, or json: one object per line (time, level, logger, message)")
      ->check(CLI::IsMember({"text", "json"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  try {
    return run(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "parapm-worker: %s\n", e.what());
    return 2;
  }
}
