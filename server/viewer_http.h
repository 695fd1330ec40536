// The coordinator's HTTP side (parapm-coordinator --http ADDR): the viewer's page and the data
// it reads, over the same stores as the gRPC API. Routes (docs/VIEWER.md has the contract):
//   GET /                      the page (and its scripts: the files embedded at build time)
//   GET /api/jobs              {"jobs": [Job, ...]}, newest first, as the API's JSON
//   GET /api/jobs/JOB          Job
//   GET /api/jobs/JOB/pm       the job's .pm file, streamed as stored (its hash checked first)
//   GET /metrics               the coordinator's Prometheus metrics (coordinator_metrics.h)
// Errors are JSON {"error": message} with the HTTP status of their kind (400, 401, 404, 409,
// 500). With a token (required beyond loopback, as for gRPC) every /api route needs it, as
// "Authorization: Bearer TOKEN" or "?token=TOKEN" (a page cannot set headers on a link).
//
// Resources a client can hold are bounded: a fixed pool of threads (one per connection being
// served; more connections wait in the kernel's queue), read and write timeouts (a client that
// stops reading is cut off), requests without a body, a bounded number of requests per
// keep-alive connection. Thread-safe: start() once, stop() from any thread.
#pragma once

#include <memory>
#include <string>

#include "http_endpoint.h"
#include "rpc_security.h"

namespace parapm::service {

class Coordinator;

struct ViewerConfig {
  std::string listen = "127.0.0.1:0";  // host:port (port 0: any free)
  std::string token;                   // "" : none required (loopback only)
  rpc::TlsFiles tls;                   // HTTPS when a certificate is given
  unsigned threads = 8;                // connections served at once
  unsigned read_timeout_s = 10, write_timeout_s = 60;
};

class ViewerServer {
 public:
  // Throws Error(kInvalidInput) for a bad address, or beyond loopback without a token.
  ViewerServer(Coordinator& coordinator, ViewerConfig config);
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;

  // Binds and serves on a thread of its own; returns the port. Throws Error(kIo) when the
  // address cannot be bound.
  int start();
  void stop() { http_.stop(); }
  // http(s)://HOST:PORT/ as a browser on this machine reaches it.
  std::string url() const { return http_.url(); }

 private:
  void add_routes();

  Coordinator& coordinator_;
  ViewerConfig config_;
  rpc::HttpEndpoint http_;
};

}  // namespace parapm::service
