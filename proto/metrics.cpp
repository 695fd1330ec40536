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

MetricsServer::MetricsServer(std::shared_ptr<prometheus::Registry> registry,
                             MetricsEndpoint endpoint, std::function<void()> before_scrape)
    : registry_(std::move(registry)),
      before_scrape_(std::move(before_scrape)),
      http_({.what = "metrics",
             .flag = "--metrics-listen",
             .listen = endpoint.listen,
             .token = endpoint.token,
             .tls = endpoint.tls}) {
  httplib::Server& server = http_.server();
  server.Get("/metrics", [this](const httplib::Request& request, httplib::Response& response) {
    if (!scrape_allowed(http_.setup().token, request.get_header_value("Authorization"))) {
      response.status = 401;
      response.set_content("a scrape needs Authorization: Bearer TOKEN\n", "text/plain");
      return;
    }
    if (before_scrape_) before_scrape_();
    response.set_content(prometheus_text(*registry_), kPrometheusContentType);
  });
  server.set_error_handler([](const httplib::Request&, httplib::Response& response) {
    if (response.status == 404)
      response.set_content("only GET /metrics is served here\n", "text/plain");
  });
}

int MetricsServer::start() {
  const int port = http_.start();
  spdlog::info("metrics: {}metrics{}", http_.url(),
               http_.setup().token.empty() ? "" : " (token required)");
  return port;
}

}  // namespace parapm::rpc
