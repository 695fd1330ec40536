#include "http_endpoint.h"

#include <httplib.h>

#include <algorithm>
#include <chrono>

#include "rpc_server.h"
#include "util/error.h"

namespace parapm::rpc {

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

HttpEndpoint::HttpEndpoint(HttpSetup setup) : setup_(std::move(setup)) {
  http_host_and_port(setup_.listen, setup_.flag);  // checked now
  if (setup_.token.empty() && !is_loopback_address(setup_.listen))
    throw_invalid("refusing to serve " + setup_.what + " on " + setup_.listen +
                  " without a token: beyond loopback every request needs one (--token-file FILE "
                  "or PARAPM_TOKEN)");
  if (setup_.tls.server_enabled()) {
    server_ = std::make_unique<httplib::SSLServer>(setup_.tls.cert_file.c_str(),
                                                   setup_.tls.key_file.c_str());
    if (!server_->is_valid())
      throw_invalid("--tls-cert / --tls-key: " + setup_.what + " cannot use them");
  } else {
    server_ = std::make_unique<httplib::Server>();
  }
  const unsigned threads = std::max(1u, setup_.threads);
  server_->new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  server_->set_read_timeout(std::chrono::seconds(setup_.read_timeout_s));
  server_->set_write_timeout(std::chrono::seconds(setup_.write_timeout_s));
  server_->set_payload_max_length(4096);  // every route is a GET
}

HttpEndpoint::~HttpEndpoint() { stop(); }

int HttpEndpoint::start() {
  const auto [host, port] = http_host_and_port(setup_.listen, setup_.flag);
  port_ = port == 0 ? server_->bind_to_any_port(host.c_str())
                    : (server_->bind_to_port(host.c_str(), port) ? port : -1);
  if (port_ <= 0) throw Error(ErrorCode::kIo, setup_.what + " cannot listen on " + setup_.listen);
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  return port_;
}

void HttpEndpoint::stop() {
  if (!thread_.joinable()) return;
  server_->stop();
  thread_.join();
}

std::string HttpEndpoint::url() const {
  return std::string(setup_.tls.server_enabled() ? "https" : "http") + "://" +
         reachable_address(setup_.listen, port_) + "/";
}

}  // namespace parapm::rpc
