// Server set-up in one place (STYLE.md): the listening port, message limits, thread quota,
// health checking and reflection; and `serve`, the bridge every handler body runs through.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "rpc_security.h"
#include "rpc_status.h"

namespace parapm::rpc {

struct ServerSetup {
  std::string listen;  // "host:port"; port 0 picks a free one
  TlsFiles tls;
  int max_threads = 64;  // the sync server's thread quota (streams hold a thread each)
  // Largest message accepted: a worker takes whole subset jobs; the coordinator only chunks.
  int max_receive_bytes = kMaxMessageBytes;
};

struct StartedServer {
  std::unique_ptr<grpc::Server> server;
  int port = 0;  // the port bound
};

// Builds and starts a server with `services`, the standard health service (serving) and
// server reflection. Throws Error(kIo) when the address cannot be bound.
StartedServer start_server(const ServerSetup& setup, const std::vector<grpc::Service*>& services);

// The address to reach a server listening on `listen` bound to `port` ("0.0.0.0:0" ->
// "127.0.0.1:<port>" for a caller on the same machine; otherwise the host with the port).
std::string reachable_address(const std::string& listen, int port);

// Runs a handler body: the token first, then `body`, any exception mapped to its status.
template <class Body>
grpc::Status serve(const TokenCheck& auth, const grpc::ServerContext* context, Body&& body) {
  if (grpc::Status s = auth.check(*context); !s.ok()) return s;
  try {
    return body();
  } catch (...) {
    return status_of_current_exception();
  }
}

}  // namespace parapm::rpc
