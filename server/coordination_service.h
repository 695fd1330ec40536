// Coordination bridge: workers register and beat; the registry does the bookkeeping.
#pragma once

#include "parapm.grpc.pb.h"
#include "rpc_security.h"
#include "worker_registry.h"

namespace parapm::service {

class CoordinationService final : public parapm::v1::Coordination::Service {
 public:
  CoordinationService(WorkerRegistry& registry, rpc::TokenCheck auth)
      : registry_(registry), auth_(std::move(auth)) {}

  grpc::Status Register(grpc::ServerContext* context, const parapm::v1::WorkerInfo* request,
                        parapm::v1::RegisterReply* reply) override;
  grpc::Status Beat(grpc::ServerContext* context, const parapm::v1::Heartbeat* request,
                    parapm::v1::HeartbeatReply* reply) override;

 private:
  WorkerRegistry& registry_;
  rpc::TokenCheck auth_;
};

}  // namespace parapm::service
