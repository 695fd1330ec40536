#include "coordinator_link.h"

#include <chrono>

#include <spdlog/spdlog.h>

#include "rpc_security.h"

namespace parapm::worker {
namespace {
constexpr unsigned kRetryMs = 500;
constexpr auto kCallTimeout = std::chrono::seconds(5);
}  // namespace

CoordinatorLink::CoordinatorLink(LinkOptions options, std::function<unsigned()> running)
    : options_(std::move(options)), running_(std::move(running)) {
  stub_ = parapm::v1::Coordination::NewStub(
      rpc::make_channel(options_.coordinator, options_.credentials));
  thread_ = std::thread([this] { loop(); });
}

CoordinatorLink::~CoordinatorLink() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool CoordinatorLink::pause(unsigned ms) {
  std::unique_lock lock(mutex_);
  wake_.wait_for(lock, std::chrono::milliseconds(ms), [this] { return stopping_; });
  return !stopping_;
}

bool CoordinatorLink::register_once() {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
  rpc::attach_token(context, options_.token);
  parapm::v1::RegisterReply reply;
  const grpc::Status status = stub_->Register(&context, options_.info, &reply);
  if (!status.ok()) {
    // Unauthenticated or refused: retrying will not help, but the operator may fix the
    // coordinator's side; keep trying, loudly.
    if (status.error_code() != grpc::StatusCode::UNAVAILABLE &&
        status.error_code() != grpc::StatusCode::DEADLINE_EXCEEDED)
      spdlog::error("coordinator {} refused the registration: {}", options_.coordinator,
                    status.error_message());
    return false;
  }
  worker_id_ = reply.worker_id();
  heartbeat_ms_ = std::max(100u, reply.heartbeat_ms());
  spdlog::info("registered with coordinator {} as {} (beat every {} ms)", options_.coordinator,
               worker_id_, heartbeat_ms_);
  return true;
}

grpc::StatusCode CoordinatorLink::beat_once() {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + kCallTimeout);
  rpc::attach_token(context, options_.token);
  parapm::v1::Heartbeat beat;
  beat.set_worker_id(worker_id_);
  beat.set_running_subsets(running_());
  parapm::v1::HeartbeatReply reply;
  return stub_->Beat(&context, beat, &reply).error_code();
}

void CoordinatorLink::loop() {
  bool warned = false;
  while (true) {
    if (worker_id_.empty()) {
      if (register_once()) {
        warned = false;
      } else {
        if (!warned)
          spdlog::warn("coordinator {} not reachable yet; retrying every {} ms",
                       options_.coordinator, kRetryMs);
        warned = true;
        if (!pause(kRetryMs)) return;
        continue;
      }
    }
    if (!pause(heartbeat_ms_)) return;
    const grpc::StatusCode code = beat_once();
    if (code == grpc::StatusCode::NOT_FOUND) {
      spdlog::info("coordinator {} forgot worker {} (restarted?): registering again",
                   options_.coordinator, worker_id_);
      worker_id_.clear();
    } else if (code != grpc::StatusCode::OK && !warned) {
      spdlog::warn("heartbeat to coordinator {} failed ({}); retrying", options_.coordinator,
                   int(code));
      warned = true;
    } else if (code == grpc::StatusCode::OK) {
      warned = false;
    }
  }
}

}  // namespace parapm::worker
