#include "metrics.h"

#include <httplib.h>

#include <prometheus/text_serializer.h>
#include <spdlog/spdlog.h>

#include "util/error.h"

namespace parapm::rpc {

std::string prometheus_text(prometheus::Registry& registry) {
  return prometheus::TextSerializer().Serialize(registry.Collect());
}

bool scrape_allowed(const std::string& token, const std::string& authorization) {
  return token.empty() || authorization == "Bearer " + token;
}

std::pair<std::string, int> http_host_and_port(const std::string& listen, const std::string& flag) {
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos || colon + 1 == listen.size())
    throw_invalid(flag + " wants host:port, got '" + listen + "'");
  std::string host = listen.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
    host = host.substr(1, host.size() - 2);
  int port = -1;
  try {
    size_t used = 0;
    port = std::stoi(listen.substr(colon + 1), &used);
    if (used != listen.size() - colon - 1) port = -1;
  } catch (const std::exception&) {
  }
  if (port < 0 || port > 65535) throw_invalid(flag + ": bad port in '" + listen + "'");
  return {host.empty() ? "0.0.0.0" : host, port};
}

MetricsServer::MetricsServer(std::shared_ptr<prometheus::Registry> registry,
                             MetricsEndpoint endpoint, std::function<void()> before_scrape)
    : registry_(std::move(registry)),
      endpoint_(std::move(endpoint)),
      before_scrape_(std::move(before_scrape)) {
  http_host_and_port(endpoint_.listen, "--metrics-listen");  // checked now
  if (endpoint_.token.empty() && !is_loopback_address(endpoint_.listen))
    throw_invalid("refusing to serve metrics on " + endpoint_.listen +
                  " without a token: beyond loopback every scrape needs one (--token-file FILE "
                  "or PARAPM_TOKEN)");
  if (endpoint_.tls.server_enabled()) {
    server_ = std::make_unique<httplib::SSLServer>(endpoint_.tls.cert_file.c_str(),
                                                   endpoint_.tls.key_file.c_str());
    if (!server_->is_valid())
      throw_invalid("--tls-cert / --tls-key: the metrics endpoint cannot use them");
  } else {
    server_ = std::make_unique<httplib::Server>();
  }
  server_->new_task_queue = [] { return new httplib::ThreadPool(2); };
  server_->set_read_timeout(std::chrono::seconds(10));
  server_->set_write_timeout(std::chrono::seconds(10));
  server_->set_payload_max_length(4096);
  server_->Get("/metrics", [this](const httplib::Request& request, httplib::Response& response) {
    if (!scrape_allowed(endpoint_.token, request.get_header_value("Authorization"))) {
      response.status = 401;
      response.set_content("a scrape needs Authorization: Bearer TOKEN\n", "text/plain");
      return;
    }
    if (before_scrape_) before_scrape_();
    response.set_content(prometheus_text(*registry_), kPrometheusContentType);
  });
  server_->set_error_handler([](const httplib::Request&, httplib::Response& response) {
    if (response.status == 404)
      response.set_content("only GET /metrics is served here\n", "text/plain");
  });
}

MetricsServer::~MetricsServer() { stop(); }

int MetricsServer::start() {
  const auto [host, port] = http_host_and_port(endpoint_.listen, "--metrics-listen");
  const int bound = port == 0 ? server_->bind_to_any_port(host.c_str())
                              : (server_->bind_to_port(host.c_str(), port) ? port : -1);
  if (bound <= 0) throw Error(ErrorCode::kIo, "cannot serve metrics on " + endpoint_.listen);
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  spdlog::info("metrics: {}://{}/metrics{}", endpoint_.tls.server_enabled() ? "https" : "http",
               host + ":" + std::to_string(bound),
               endpoint_.token.empty() ? "" : " (token required)");
  return bound;
}

void MetricsServer::stop() {
  if (!thread_.joinable()) return;
  server_->stop();
  thread_.join();
}

}  // namespace parapm::rpc
