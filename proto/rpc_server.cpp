#include "rpc_server.h"

#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/health_check_service_interface.h>

#include "util/error.h"

namespace parapm::rpc {

StartedServer start_server(const ServerSetup& setup, const std::vector<grpc::Service*>& services) {
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  StartedServer started;
  builder.AddListeningPort(setup.listen, server_credentials(setup.tls), &started.port);
  builder.SetMaxReceiveMessageSize(setup.max_receive_bytes);
  builder.SetMaxSendMessageSize(kMaxMessageBytes);
  grpc::ResourceQuota quota("parapm");
  quota.SetMaxThreads(setup.max_threads);
  builder.SetResourceQuota(quota);
  // Accept the clients' keepalive pings (rpc_security.cpp, make_channel).
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS, 5000);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PING_STRIKES, 0);
  for (grpc::Service* service : services) builder.RegisterService(service);
  started.server = builder.BuildAndStart();
  if (!started.server || started.port == 0)
    throw Error(ErrorCode::kIo, "cannot listen on " + setup.listen +
                                    " (address in use, or not an address of this machine)");
  return started;
}

std::string reachable_address(const std::string& listen, int port) {
  std::string host = listen.substr(0, listen.rfind(':'));
  if (host.empty() || host == "0.0.0.0" || host == "[::]" || host == "::") host = "127.0.0.1";
  return host + ":" + std::to_string(port);
}

}  // namespace parapm::rpc
