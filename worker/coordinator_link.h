// The worker's side of Coordination: registers with the coordinator and beats at the interval
// it asks for, in a background thread. When the coordinator is down the worker keeps trying;
// when it answers NOT_FOUND to a beat (it restarted and forgot the worker), the worker
// registers again. So workers and coordinator may start, stop and restart in any order.
#pragma once

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <grpcpp/grpcpp.h>

#include "parapm.grpc.pb.h"

namespace parapm::worker {

struct LinkOptions {
  std::string coordinator;  // address
  std::shared_ptr<grpc::ChannelCredentials> credentials;
  std::string token;
  parapm::v1::WorkerInfo info;  // what the worker announces
};

class CoordinatorLink {
 public:
  // `running` tells the beat how many subsets run now.
  CoordinatorLink(LinkOptions options, std::function<unsigned()> running);
  ~CoordinatorLink();  // stops the thread
  CoordinatorLink(const CoordinatorLink&) = delete;
  CoordinatorLink& operator=(const CoordinatorLink&) = delete;

 private:
  void loop();
  bool register_once();
  // OK, NOT_FOUND (register again) or another failure.
  grpc::StatusCode beat_once();
  // Sleeps up to `ms`; false when stopping.
  bool pause(unsigned ms);

  LinkOptions options_;
  std::function<unsigned()> running_;
  std::unique_ptr<parapm::v1::Coordination::Stub> stub_;
  std::string worker_id_;
  unsigned heartbeat_ms_ = 1000;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace parapm::worker
