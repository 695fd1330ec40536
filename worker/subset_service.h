// The worker's WorkerService: runs one subset job per call with the engine's simplify_subset,
// the very function of the in-process build, and streams its result back: progress while it
// runs, then the collapse records in batches, then the summary (state, stats, times). The
// call's deadline and cancellation reach the engine through a CancelToken. A job of a build
// keeps state (HeldStateCache: a quadric job's free vertices' quadrics at its end, an energy
// job's sample points) for the build's later jobs, whose requests leave out what it holds
// (engine/parallel/held_state.h).
#pragma once

#include <atomic>
#include <condition_variable>
#include <mutex>

#include "held_state_cache.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "parapm.grpc.pb.h"
#include "rpc_security.h"
#include "worker_metrics.h"

namespace parapm::worker {

class SubsetService final : public parapm::v1::WorkerService::Service {
 public:
  // At most `slots` subsets run at once; further calls wait for a slot (cancellable). Each
  // call's outcome, time and bytes go to `metrics`; a quadric job's quadrics at its end to
  // `held` (both outlive the service).
  SubsetService(rpc::TokenCheck auth, unsigned slots, WorkerMetrics& metrics, HeldStateCache& held);

  grpc::Status SimplifySubset(grpc::ServerContext* context,
                              const parapm::v1::SubsetRequest* request,
                              grpc::ServerWriter<parapm::v1::SubsetProgress>* writer) override;

  unsigned running() const { return running_.load(); }

 private:
  // The call's outcome in the metrics.
  void record_outcome(const grpc::Status& status, double seconds, uint64_t bytes_sent);
  // Puts back into the job's state what its request left out (`held`, its held_ids: a
  // quadric job's quadrics, an energy job's sample points); a status other than OK when this
  // worker does not hold them.
  grpc::Status restore_held_state(const parapm::v1::SubsetRequest& request,
                                  const std::vector<uint32_t>& held, SubsetJob& job);
  // Waits for a free slot; false when the call was cancelled meanwhile. `team`: the slots left
  // idle as it starts, shared with the jobs running (JobTeam: the energy's rich collapses of a
  // round's last few jobs use this worker's idle cores; the same records either way).
  bool acquire_slot(grpc::ServerContext* context, JobTeam& team);
  void release_slot();

  rpc::TokenCheck auth_;
  unsigned slots_;
  WorkerMetrics& metrics_;
  HeldStateCache& held_;
  std::atomic<unsigned> running_{0};
  std::mutex mutex_;
  std::condition_variable slot_freed_;
  unsigned busy_ = 0;
};

}  // namespace parapm::worker
