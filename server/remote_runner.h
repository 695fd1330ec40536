// The coordinator's SubsetRunner: sends a round's subset jobs to worker daemons
// (WorkerService.SimplifySubset), collects their streamed records and summaries, and
// dispatches a subset again when its worker dies (missed heartbeats, broken stream) or
// fails for a reason of its own. The results are the workers' simplify_subset results, so
// the PM is byte-identical to the in-process build's.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>

#include <grpcpp/grpcpp.h>

#include "held_state_ledger.h"
#include "parallel/parallel_build.h"
#include "worker_registry.h"

namespace parapm::service {

// Channels to workers by address, reused across rounds and jobs. Thread-safe.
class WorkerChannels {
 public:
  explicit WorkerChannels(std::shared_ptr<grpc::ChannelCredentials> credentials);
  std::shared_ptr<grpc::Channel> get(const std::string& address);

 private:
  std::shared_ptr<grpc::ChannelCredentials> credentials_;
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<grpc::Channel>> channels_;
};

struct SubsetEvent {
  enum class Kind { kStarted, kDone, kRetry };
  Kind kind = Kind::kStarted;
  uint32_t round = 0, subset = 0;
  std::string worker;  // its name; "coordinator" when it ran in-process
  uint32_t attempt = 1;
  double seconds = 0, cpu_seconds = 0;
  double transfer_seconds = 0;  // the call's time beyond the worker's (TransportStats)
  uint64_t collapses = 0;
  std::string reason;  // kRetry: why
};

struct RemoteOptions {
  std::string job_id;  // for the workers' logs
  std::string token;   // sent to the workers
  // Attempts of one subset (on different workers where possible) before the job fails.
  unsigned max_attempts = 4;
  // When no worker is registered, the coordinator runs subsets itself on this many threads
  // (0: it waits for a worker instead).
  unsigned local_threads = 0;
};

// What moving the jobs cost, summed over every subset call of the runner's life.
struct TransportStats {
  double encode_seconds = 0;  // subset jobs to bytes, in the coordinator (before dispatch)
  // Per call: its wall time at the coordinator minus the worker's own time for the subset and
  // its wait for a slot there when queued ahead (left: sending the job, decoding it,
  // streaming and decoding the records), summed.
  double call_overhead_seconds = 0;
  uint64_t job_bytes = 0;     // of every call sent, retries included
  uint64_t result_bytes = 0;  // record batches and summaries
  uint64_t calls = 0;
  // Items of state left out of the jobs done, their workers holding them (quadrics or
  // points: held_state.h), and those the jobs carried.
  uint64_t held_items = 0;
  uint64_t sent_items = 0;
};

class RemoteRunner : public SubsetRunner {
 public:
  RemoteRunner(WorkerRegistry& registry, WorkerChannels& channels, RemoteOptions options,
               std::function<void(const SubsetEvent&)> on_event);
  std::vector<SubsetResult> run(std::vector<SubsetJob>& jobs, const CancelToken* cancel) override;
  const TransportStats& transport() const { return transport_; }

 private:
  class Dispatch;  // one run's state (remote_runner.cpp)
  TransportStats transport_;
  // The workers keep this build's state under it (held_state.h), and a later job goes to the
  // worker holding most of its own, without it.
  std::string build_key_;
  HeldStateLedger held_;  // what they keep
  // Workers that lost state this build had left with them: none is left out for them again.
  std::set<std::string> distrusted_;
  WorkerRegistry& registry_;
  WorkerChannels& channels_;
  RemoteOptions options_;
  std::function<void(const SubsetEvent&)> on_event_;
};

}  // namespace parapm::service
