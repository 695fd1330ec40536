#include "coordination_service.h"

#include <cmath>

#include "rpc_server.h"
#include "util/error.h"

namespace parapm::service {

grpc::Status CoordinationService::Register(grpc::ServerContext* context,
                                           const parapm::v1::WorkerInfo* request,
                                           parapm::v1::RegisterReply* reply) {
  return rpc::serve(auth_, context, [&] {
    if (request->address().empty() || request->address().size() > 255)
      throw_invalid("worker address must be host:port (1 to 255 characters)");
    if (request->threads() > 4096) throw_invalid("worker threads must be at most 4096");
    if (!std::isfinite(request->capacity()) || request->capacity() < 0)
      throw_invalid("worker capacity must be a finite number >= 0 (0: 1)");
    WorkerDescription worker;
    worker.address = request->address();
    worker.name = request->name().empty() ? request->address() : request->name().substr(0, 255);
    worker.threads = request->threads();
    worker.capacity = request->capacity() > 0 ? request->capacity() : 1;
    reply->set_worker_id(registry_.add(worker));
    reply->set_heartbeat_ms(uint32_t(registry_.heartbeat().count()));
    return grpc::Status::OK;
  });
}

grpc::Status CoordinationService::Beat(grpc::ServerContext* context,
                                       const parapm::v1::Heartbeat* request,
                                       parapm::v1::HeartbeatReply*) {
  return rpc::serve(auth_, context, [&] {
    if (!registry_.beat(request->worker_id(), request->running_subsets()))
      throw Error(ErrorCode::kNotFound,
                  "unknown worker '" + request->worker_id() + "': register again");
    return grpc::Status::OK;
  });
}

}  // namespace parapm::service
