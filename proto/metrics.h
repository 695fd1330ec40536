// A daemon's Prometheus metrics: the text exposition of a registry (prometheus-cpp), and a
// small HTTP endpoint that serves it at GET /metrics (parapm-worker --metrics-listen; the
// coordinator serves /metrics on its viewer's port instead, server/viewer_http.h).
//
// Same security as the daemon's gRPC side: with a token (required beyond loopback) a scrape
// must send "Authorization: Bearer TOKEN" (Prometheus: authorization.credentials_file); TLS
// when the daemon has a certificate. Bounded: two connections served at once, read and write
// timeouts, no request bodies.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include <prometheus/registry.h>

#include "http_endpoint.h"
#include "rpc_security.h"

namespace parapm::rpc {

// The registry's metrics in Prometheus' text format (version 0.0.4).
std::string prometheus_text(prometheus::Registry& registry);

// Content-Type of prometheus_text.
inline constexpr const char* kPrometheusContentType = "text/plain; version=0.0.4; charset=utf-8";

// True when `authorization` (the request's Authorization header) carries `token`, or no
// token is required.
bool scrape_allowed(const std::string& token, const std::string& authorization);

struct MetricsEndpoint {
  std::string listen;  // host:port (port 0: any free)
  std::string token;   // "" : none required (loopback only)
  TlsFiles tls;        // HTTPS when a certificate is given
};

class MetricsServer {
 public:
  // `before_scrape` refreshes gauges read from the daemon's state (called on the serving
  // thread, once per scrape). Throws Error(kInvalidInput) for a bad address, or beyond
  // loopback without a token.
  MetricsServer(std::shared_ptr<prometheus::Registry> registry, MetricsEndpoint endpoint,
                std::function<void()> before_scrape = {});
  MetricsServer(const MetricsServer&) = delete;
  MetricsServer& operator=(const MetricsServer&) = delete;

  // Binds and serves on a thread of its own; returns the port. Throws Error(kIo).
  int start();
  void stop() { http_.stop(); }

 private:
  std::shared_ptr<prometheus::Registry> registry_;
  std::function<void()> before_scrape_;
  HttpEndpoint http_;
};

}  // namespace parapm::rpc
