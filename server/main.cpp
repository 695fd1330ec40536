// parapm-coordinator: the ParaPM service. Accepts uploads, queues jobs, partitions each mesh
// and sends its subsets to the registered workers, merges their records into the PM, stores
// it (SQLite + content-addressed blobs under --data) and serves it whole, by level or as a
// vsplit stream. Stops cleanly on SIGINT / SIGTERM; a restart resumes unfinished jobs.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <optional>
#include <thread>

#include <spdlog/spdlog.h>

#include "call_admission.h"
#include "coordination_service.h"
#include "coordinator.h"
#include "daemon.h"
#include "mesh_service.h"
#include "rpc_server.h"
#include "storage/blob_store.h"
#include "util/memory.h"
#include "viewer_http.h"

namespace {

struct CoordinatorArgs {
  std::string listen = "127.0.0.1:50051";
  std::string data = "parapm-data";
  uint64_t max_upload_mb = 2048;
  uint64_t max_mesh_mb = 4096;
  uint32_t parallelism = 4;
  unsigned max_running_jobs = 2;
  unsigned local_threads = 0;
  unsigned heartbeat_ms = 1000;
  std::string token_file;
  parapm::rpc::TlsFiles tls;
  bool worker_tls = false;
  std::string port_file;
  std::string http;  // the viewer's address; "" : no viewer
  std::string http_port_file;
  unsigned http_threads = 8;
  std::string log_level = "info";
  std::string log_format = "text";
  bool verify = false;
  parapm::rpc::CallLimits streams;
  parapm::rpc::CallLimits unary{"calls", 32, 8};
  double stream_idle_s = 60, stream_total_s = 3600;
  double retain_days = 0, retain_gb = 0, retention_check_s = 600;
};

// Upload chunks carry at most 4 MiB of data (parapm.proto); a message a little larger holds
// its other fields.
constexpr int kMaxChunkMessageBytes = (4 << 20) + (64 << 10);

// --verify: every blob hashed again; exit status 0 when all match, 1 otherwise.
int verify_store(const CoordinatorArgs& args) {
  using parapm::service::BlobStore;
  parapm::rpc::set_up_logging("coordinator", args.log_level, args.log_format);
  const BlobStore::VerifyReport report = BlobStore::verify(args.data);
  std::printf("%llu blobs, %llu bytes checked in %s: %zu corrupt\n",
              static_cast<unsigned long long>(report.blobs),
              static_cast<unsigned long long>(report.bytes), args.data.c_str(),
              report.corrupt.size());
  for (const std::string& name : report.corrupt) std::printf("corrupt: %s\n", name.c_str());
  return report.corrupt.empty() ? 0 : 1;
}

// Written once listening, atomically: a script polling for the file gets a usable port.
void write_port_file(const std::string& path, int port) {
  const std::string temp = path + ".tmp";
  if (FILE* f = std::fopen(temp.c_str(), "w")) {
    std::fprintf(f, "%d\n", port);
    std::fclose(f);
    std::filesystem::rename(temp, path);
  }
}

int run(CoordinatorArgs args) {
  using namespace parapm;
  rpc::set_up_logging("coordinator", args.log_level, args.log_format);
  args.streams.idle = std::chrono::milliseconds(int64_t(args.stream_idle_s * 1000));
  args.streams.total = std::chrono::milliseconds(int64_t(args.stream_total_s * 1000));
  args.unary.idle = args.streams.idle;
  args.unary.total = args.streams.total;
  const std::string token = rpc::token_for_listening(args.token_file, args.listen);
  service::CoordinatorConfig config;
  config.data_dir = args.data;
  config.max_upload_bytes = args.max_upload_mb << 20;
  config.max_mesh_bytes = args.max_mesh_mb << 20;
  config.retain_for = std::chrono::milliseconds(int64_t(args.retain_days * 86400e3));
  config.retain_bytes = uint64_t(args.retain_gb * double(1ull << 30));
  config.retention_check = std::chrono::milliseconds(int64_t(args.retention_check_s * 1000));
  config.default_parallelism = args.parallelism;
  config.max_running_jobs = args.max_running_jobs;
  config.local_threads = args.local_threads;
  config.heartbeat = std::chrono::milliseconds(args.heartbeat_ms);
  config.worker_token = token;
  config.worker_credentials = rpc::channel_credentials(args.worker_tls, args.tls);
  std::filesystem::create_directories(config.data_dir);
  service::Coordinator coordinator(config);
  rpc::CallAdmission streams(args.streams);
  rpc::CallAdmission unary(args.unary);
  service::MeshService mesh_service(coordinator, rpc::TokenCheck(token), streams, unary);
  service::CoordinationService coordination(coordinator.workers(), rpc::TokenCheck(token));
  // The viewer's options are checked before anything listens.
  std::optional<service::ViewerServer> viewer;
  if (!args.http.empty()) {
    service::ViewerConfig viewer_config;
    viewer_config.listen = args.http;
    viewer_config.token = token;
    viewer_config.tls = args.tls;
    viewer_config.threads = args.http_threads;
    viewer.emplace(coordinator, viewer_config);
  }
  rpc::ServerSetup setup;
  setup.listen = args.listen;
  setup.tls = args.tls;
  setup.max_receive_bytes = kMaxChunkMessageBytes;
  // A thread for every client call admitted, and 64 more that only the workers' calls (and
  // health checks) can take: client traffic never starves the workers' heartbeats.
  setup.max_threads = int(args.streams.max_calls + args.unary.max_calls) + 64;
  rpc::StartedServer server = rpc::start_server(setup, {&mesh_service, &coordination});
  const std::string address = rpc::reachable_address(args.listen, server.port);
  spdlog::info("listening on {} (data in {}, default p = {}, {} jobs at once{})", address,
               args.data, args.parallelism, args.max_running_jobs,
               token.empty() ? "" : ", token required");
  if (!args.port_file.empty()) write_port_file(args.port_file, server.port);
  if (viewer) {
    const int http_port = viewer->start();
    if (!args.http_port_file.empty()) write_port_file(args.http_port_file, http_port);
  }
  const std::string signal = rpc::wait_for_shutdown_signal();
  spdlog::info("{}: stopping (running jobs re-run at the next start)", signal);
  if (viewer) viewer->stop();
  coordinator.stop();  // before the calls drain, so that running jobs stop now
  server.server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
  return 0;  // ~Coordinator waits for the schedulers
}

}  // namespace

int main(int argc, char** argv) {
  parapm::rpc::block_shutdown_signals();
  parapm::map_large_blocks_alone();  // jobs run on pools of threads
  CoordinatorArgs args;
  CLI::App app{
      "parapm-coordinator: the ParaPM service. Clients upload meshes and submit jobs (parapm "
      "submit); workers (parapm-worker) register and simplify the subsets it sends them; it "
      "merges, stores and serves the Progressive Meshes."};
  app.add_option("--listen", args.listen, "address to serve on, host:port (port 0: any free)")
      ->capture_default_str();
  app.add_option("--data", args.data, "folder for the database and blobs (created if absent)")
      ->capture_default_str();
  app.add_option("--max-upload-mb", args.max_upload_mb,
                 "largest upload accepted, MiB, as sent (compressed, for a .gz)")
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 20))
      ->capture_default_str();
  app.add_option("--max-mesh-mb", args.max_mesh_mb,
                 "largest mesh file accepted once inflated, MiB (a .gz is inflated in a "
                 "stream that stops here, and after its first 64 KiB when they are no mesh)")
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 20))
      ->capture_default_str();
  app.add_option("--parallelism", args.parallelism,
                 "subsets p of a job that does not say (the PM depends on p, not on the workers)")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option("--max-running-jobs", args.max_running_jobs, "jobs built at once; others queue")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_option("--local-threads", args.local_threads,
                 "run subsets in the coordinator on this many threads while no worker is "
                 "registered (0: wait for a worker)")
      ->capture_default_str();
  app.add_option("--heartbeat-ms", args.heartbeat_ms,
                 "beat interval asked of workers; 3 missed beats and a worker is dead")
      ->check(CLI::Range(100, 60000))
      ->capture_default_str();
  app.add_option("--max-streams", args.streams.max_calls,
                 "streaming calls (uploads, watches, downloads, streams) open at once, all "
                 "clients together; more are refused with RESOURCE_EXHAUSTED")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  app.add_option("--max-streams-per-client", args.streams.max_per_client,
                 "streaming calls open at once from one client address")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  app.add_option("--max-calls", args.unary.max_calls,
                 "unary client calls (submit, job queries, cancel, delete) in progress at once, "
                 "all clients together; more are refused with RESOURCE_EXHAUSTED")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  app.add_option("--max-calls-per-client", args.unary.max_per_client,
                 "unary calls in progress at once from one client address")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  app.add_option("--stream-idle-s", args.stream_idle_s,
                 "a call that moves no message for this long is closed (seconds)")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_option("--stream-total-s", args.stream_total_s,
                 "a stream open for longer than this is closed (seconds; a watch is then "
                 "resumed by the client)")
      ->check(CLI::Range(1.0, 7.0 * 86400))
      ->capture_default_str();
  app.add_option("--retain-days", args.retain_days,
                 "delete jobs that ended this many days ago, and meshes as old with no job left "
                 "(0: keep them)")
      ->check(CLI::Range(0.0, 36500.0))
      ->capture_default_str();
  app.add_option("--retain-gb", args.retain_gb,
                 "while the stored uploads and PMs take more than this (GiB), delete the oldest "
                 "ended jobs, then the oldest meshes without a job uploaded over an hour ago "
                 "(0: no bound)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--retention-check-s", args.retention_check_s,
                 "how often the retention is applied (seconds; also at start)")
      ->check(CLI::Range(0.1, 86400.0))
      ->capture_default_str();
  app.add_option("--token-file", args.token_file,
                 "bearer token required on every call and sent to workers (else PARAPM_TOKEN; "
                 "required when listening beyond loopback)");
  app.add_option("--tls-cert", args.tls.cert_file, "PEM certificate: serve over TLS");
  app.add_option("--tls-key", args.tls.key_file, "PEM private key of --tls-cert");
  app.add_flag("--worker-tls", args.worker_tls, "call workers over TLS");
  app.add_option("--tls-ca", args.tls.ca_file,
                 "PEM roots that sign the workers' certificates (default: the system's)");
  app.add_option("--http", args.http,
                 "serve the viewer (a web page showing the jobs' PMs as they stream) and the "
                 "Prometheus metrics (/metrics) on this address, host:port (port 0: any free); "
                 "beyond loopback the token is required, and --tls-cert serves it over HTTPS");
  app.add_option("--http-threads", args.http_threads, "viewer connections served at once")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  app.add_option("--http-port-file", args.http_port_file,
                 "write the viewer's port to this file once serving (for scripts, with port 0)");
  app.add_option("--port-file", args.port_file,
                 "write the port listened on to this file once serving (for scripts, with port 0)");
  app.add_option("--log-level", args.log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  app.add_option("--log-format", args.log_format,
                 "text, or json: one object per line (time, level, logger, message)")
      ->check(CLI::IsMember({"text", "json"}))
      ->capture_default_str();
  app.add_flag("--verify", args.verify,
               "check every stored blob of --data against its hash, print the corrupt ones and "
               "exit (status 1 when any is corrupt); safe beside a running coordinator");
  CLI11_PARSE(app, argc, argv);
  try {
    if (args.verify) return verify_store(args);
    return run(args);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "parapm-coordinator: %s\n", e.what());
    return 2;
  }
}
