// An HTTP(S) server of a daemon's (cpp-httplib), with the bounds and checks every one needs:
// a valid host:port, a token beyond loopback, TLS when a certificate is given, a fixed pool of
// threads (one per connection served; more wait in the kernel's queue), read and write
// timeouts, requests without a body. The viewer and the worker's metrics endpoint are two.
// Routes are the owner's: add them to server() before start(). Thread-safe: start() once,
// stop() from any thread.
#pragma once

#include <memory>
#include <string>
#include <thread>
#include <utility>

#include "rpc_security.h"

namespace httplib {
class Server;
}

namespace parapm::rpc {

struct HttpSetup {
  std::string what;    // in messages: "the viewer", "metrics"
  std::string flag;    // the option that gave `listen`, in messages: "--http"
  std::string listen;  // host:port (port 0: any free)
  std::string token;   // "" : none required (loopback only)
  TlsFiles tls;        // HTTPS when a certificate is given
  unsigned threads = 2;
  unsigned read_timeout_s = 10, write_timeout_s = 10;
};

class HttpEndpoint {
 public:
  // Throws Error(kInvalidInput) for a bad address, beyond loopback without a token, or TLS
  // files the server cannot use.
  explicit HttpEndpoint(HttpSetup setup);
  ~HttpEndpoint();  // stop()
  HttpEndpoint(const HttpEndpoint&) = delete;
  HttpEndpoint& operator=(const HttpEndpoint&) = delete;

  httplib::Server& server() { return *server_; }
  const HttpSetup& setup() const { return setup_; }
  // Binds and serves on a thread of its own; returns the port. Throws Error(kIo).
  int start();
  void stop();
  // scheme://HOST:PORT/ as a client on this machine reaches it (after start()).
  std::string url() const;

 private:
  HttpSetup setup_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

// Splits "host:port" (host may be [v6]; an empty host is every address); throws
// Error(kInvalidInput) naming `flag`.
std::pair<std::string, int> http_host_and_port(const std::string& listen, const std::string& flag);

}  // namespace parapm::rpc
