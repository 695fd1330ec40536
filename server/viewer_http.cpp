#include "viewer_http.h"

#include <httplib.h>

#include <algorithm>
#include <cctype>
#include <chrono>

#include <google/protobuf/util/json_util.h>
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include "coordinator.h"
#include "metrics.h"
#include "rpc_server.h"
#include "util/error.h"
#include "viewer_assets.h"

namespace parapm::service {
namespace {

// Bytes handed to the socket per write of a streamed .pm: the page decodes as they arrive.
constexpr size_t kStreamChunkBytes = 64 << 10;
// Requests served on one keep-alive connection before it is closed.
constexpr int kRequestsPerConnection = 100;

int http_status_of(ErrorCode code) {
  switch (code) {
    case ErrorCode::kInvalidInput:
      return 400;
    case ErrorCode::kNotFound:
      return 404;
    case ErrorCode::kFailedPrecondition:
      return 409;
    case ErrorCode::kResourceExhausted:
      return 429;
    case ErrorCode::kCancelled:
    case ErrorCode::kDeadlineExceeded:
      return 503;
    default:
      return 500;
  }
}

void send_error(httplib::Response& response, int status, const std::string& message) {
  response.status = status;
  // (Bytes of a request's path that are not UTF-8 are replaced, not passed on.)
  response.set_content(nlohmann::json{{"error", message}}.dump(
                           2, ' ', false, nlohmann::json::error_handler_t::replace) +
                           "\n",
                       "application/json");
}

std::string job_json(const parapm::v1::Job& job) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string out;
  if (!google::protobuf::util::MessageToJsonString(job, &out, options).ok())
    throw_internal("a job does not print as JSON");
  return out;
}

// A job id as the API makes them: short, of letters, digits and '-'. Anything else is refused
// before it reaches the store.
bool plausible_id(const std::string& id) {
  return !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
}

}  // namespace

ViewerServer::ViewerServer(Coordinator& coordinator, ViewerConfig config)
    : coordinator_(coordinator),
      config_(std::move(config)),
      http_({.what = "the viewer",
             .flag = "--http",
             .listen = config_.listen,
             .token = config_.token,
             .tls = config_.tls,
             .threads = config_.threads,
             .read_timeout_s = config_.read_timeout_s,
             .write_timeout_s = config_.write_timeout_s}) {
  http_.server().set_keep_alive_max_count(kRequestsPerConnection);
  add_routes();
}

int ViewerServer::start() {
  const int port = http_.start();
  spdlog::info("viewer: {}{}", url(), config_.token.empty() ? "" : " (token required)");
  return port;
}

void ViewerServer::add_routes() {
  // Every response: no sniffing, scripts only from here.
  http_.server().set_post_routing_handler([](const httplib::Request&, httplib::Response& response) {
    response.set_header("X-Content-Type-Options", "nosniff");
    response.set_header("Content-Security-Policy",
                        "default-src 'self'; style-src 'self' 'unsafe-inline'");
    response.set_header("Cache-Control", "no-store");
  });
  // The API's errors as JSON with their status; the authorisation first.
  auto api = [this](auto handler) {
    return [this, handler](const httplib::Request& request, httplib::Response& response) {
      if (!config_.token.empty()) {
        const std::string given = request.has_param("token")
                                      ? request.get_param_value("token")
                                      : request.get_header_value("Authorization");
        if (given != config_.token && given != "Bearer " + config_.token)
          return send_error(response, 401,
                            given.empty() ? "this viewer needs a token: open the page with "
                                            "#token=TOKEN, or send Authorization: Bearer TOKEN"
                                          : "the token is not this coordinator's");
      }
      try {
        handler(request, response);
      } catch (const Error& e) {
        send_error(response, http_status_of(e.code()), e.what());
      } catch (const std::exception& e) {
        spdlog::error("viewer: {} {}: {}", request.method, request.path, e.what());
        send_error(response, 500, "internal error; the coordinator's log has the details");
      }
    };
  };
  auto job_id_of = [](const httplib::Request& request) {
    const std::string id = request.matches[1];
    if (!plausible_id(id)) throw_invalid("'" + id.substr(0, 64) + "' is not a job id");
    return id;
  };

  http_.server().Get("/api/jobs", api([this](const httplib::Request&, httplib::Response& response) {
                       std::string out = "{\"jobs\": [";
                       bool first = true;
                       for (const parapm::v1::Job& job : coordinator_.jobs(1000)) {
                         out += first ? "\n" : ",\n";
                         out += job_json(job);
                         first = false;
                       }
                       response.set_content(out + "\n]}\n", "application/json");
                     }));
  http_.server().Get(R"(/api/jobs/([^/]+))", api([this, job_id_of](const httplib::Request& request,
                                                                   httplib::Response& response) {
                       response.set_content(job_json(coordinator_.job(job_id_of(request))) + "\n",
                                            "application/json");
                     }));
  http_.server().Get(
      R"(/api/jobs/([^/]+)/pm)",
      api([this, job_id_of](const httplib::Request& request, httplib::Response& response) {
        const std::shared_ptr<const LoadedPm> loaded = coordinator_.pm(job_id_of(request));
        response.set_header("X-ParaPM-Vsplits", std::to_string(loaded->pm.splits.size()));
        response.set_content_provider(
            loaded->bytes.size(), "application/octet-stream",
            [loaded](size_t offset, size_t length, httplib::DataSink& sink) {
              const size_t n = std::min(length, kStreamChunkBytes);
              return sink.write(loaded->bytes.data() + offset, n);
            });
      }));
  // Prometheus' scrape (docs/OPERATIONS.md): with a token, in the Authorization header.
  http_.server().Get(
      "/metrics", [this](const httplib::Request& request, httplib::Response& response) {
        if (!rpc::scrape_allowed(config_.token, request.get_header_value("Authorization")))
          return send_error(response, 401, "a scrape needs Authorization: Bearer TOKEN");
        coordinator_.refresh_metrics();
        response.set_content(rpc::prometheus_text(*coordinator_.metrics().registry),
                             rpc::kPrometheusContentType);
      });
  http_.server().Get(R"(/api/.*)",
                     [](const httplib::Request& request, httplib::Response& response) {
                       send_error(response, 404, "no such route: " + request.path.substr(0, 200));
                     });
  // Browsers ask for an icon on their own: none, without an error in the page's console.
  http_.server().Get("/favicon.ico", [](const httplib::Request&, httplib::Response& response) {
    response.status = 204;
  });
  // The page's files.
  http_.server().Get(
      R"(/([^/]*))", [](const httplib::Request& request, httplib::Response& response) {
        std::string path = request.matches[1];
        if (path.empty()) path = "index.html";
        for (const ViewerAsset& asset : viewer_assets())
          if (asset.path == path) {
            response.set_content(std::string(asset.bytes), std::string(asset.content_type));
            return;
          }
        send_error(response, 404, "no such file: " + path.substr(0, 200));
      });
}

}  // namespace parapm::service
