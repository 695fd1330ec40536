#include "remote_runner.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <set>
#include <thread>

#include <spdlog/spdlog.h>

#include "parallel/job_codec.h"
#include "parallel/simplify_subset.h"
#include "parapm.grpc.pb.h"
#include "rpc_security.h"
#include "rpc_status.h"
#include "util/clock.h"
#include "util/error.h"

namespace parapm::service {

WorkerChannels::WorkerChannels(std::shared_ptr<grpc::ChannelCredentials> credentials)
    : credentials_(std::move(credentials)) {}

std::shared_ptr<grpc::Channel> WorkerChannels::get(const std::string& address) {
  std::lock_guard lock(mutex_);
  auto& channel = channels_[address];
  if (!channel) channel = rpc::make_channel(address, credentials_);
  return channel;
}

namespace {

// One subset on its way: a call to a worker (or an in-process run), on its own thread.
struct Flight {
  size_t index = 0;
  WorkerSlot slot;  // worker_id empty: in-process
  uint32_t attempt = 1;
  std::chrono::steady_clock::time_point start;
  grpc::ClientContext context;
  std::thread thread;
  std::atomic<bool> finished{false};
  grpc::Status status;
  SubsetResult result;
  double call_seconds = 0;  // wall, at the coordinator
  uint64_t result_bytes = 0;
};

// Reads the worker's stream into flight.result; the status says how it ended. A worker that
// sends what does not decode is treated like one that failed (its subset goes elsewhere).
void call_worker(Flight& flight, parapm::v1::WorkerService::Stub& stub,
                 const parapm::v1::SubsetRequest& request) {
  const auto start = std::chrono::steady_clock::now();
  auto reader = stub.SimplifySubset(&flight.context, request);
  parapm::v1::SubsetProgress message;
  bool summary = false;
  std::string broken;
  while (reader->Read(&message)) {
    try {
      if (message.has_record_batch()) {
        decode_collapse_records(message.record_batch(), flight.result.records);
        flight.result_bytes += message.record_batch().size();
      } else if (message.has_summary()) {
        decode_subset_summary(message.summary(), flight.result);
        flight.result_bytes += message.summary().size();
        summary = true;
      }
    } catch (const std::exception& e) {
      broken = e.what();
      flight.context.TryCancel();
      break;
    }
  }
  flight.status = reader->Finish();
  flight.call_seconds = seconds_since(start);
  if (!broken.empty())
    flight.status = {grpc::StatusCode::DATA_LOSS, "the worker's reply does not decode: " + broken};
  else if (flight.status.ok() && !summary)
    flight.status = {grpc::StatusCode::DATA_LOSS, "the worker's stream ended without a summary"};
  else if (flight.status.ok() &&
           (flight.result.round != request.round() || flight.result.subset != request.subset()))
    flight.status = {grpc::StatusCode::DATA_LOSS, "the worker answered for another subset"};
}

}  // namespace

RemoteRunner::RemoteRunner(WorkerRegistry& registry, WorkerChannels& channels,
                           RemoteOptions options, std::function<void(const SubsetEvent&)> on_event)
    : registry_(registry),
      channels_(channels),
      options_(std::move(options)),
      on_event_(std::move(on_event)) {}

std::vector<SubsetResult> RemoteRunner::run(std::vector<SubsetJob>& jobs,
                                            const CancelToken* cancel) {
  const size_t n = jobs.size();
  std::vector<SubsetResult> results(n);
  std::vector<parapm::v1::SubsetRequest> requests(n);
  const auto encode_start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < n; ++i) {
    requests[i].set_job_id(options_.job_id);
    requests[i].set_round(jobs[i].round);
    requests[i].set_subset(jobs[i].subset);
    requests[i].set_job(encode_subset_job(jobs[i]));
    transport_.job_bytes += requests[i].job().size();
  }
  transport_.encode_seconds += seconds_since(encode_start);
  std::deque<size_t> pending;
  for (size_t i = 0; i < n; ++i) pending.push_back(i);
  std::vector<uint32_t> attempts(n, 0);
  std::vector<std::string> last_worker(n);
  std::vector<std::unique_ptr<Flight>> flights;
  std::mutex mutex;
  std::condition_variable changed;
  size_t done = 0;
  unsigned local_running = 0;
  bool warned_waiting = false;

  auto event = [&](SubsetEvent::Kind kind, const Flight& f) {
    if (!on_event_) return;
    SubsetEvent e;
    e.kind = kind;
    e.round = jobs[f.index].round;
    e.subset = jobs[f.index].subset;
    e.worker = f.slot.worker_id.empty() ? "coordinator" : f.slot.name;
    e.attempt = f.attempt;
    if (kind == SubsetEvent::Kind::kDone) {
      e.seconds = f.result.wall_seconds;
      e.cpu_seconds = f.result.cpu_seconds;
      if (!f.slot.worker_id.empty())
        e.transfer_seconds = std::max(0.0, f.call_seconds - f.result.wall_seconds);
      e.collapses = f.result.records.size();
    } else if (kind == SubsetEvent::Kind::kRetry) {
      e.reason = f.status.error_message();
    }
    on_event_(e);
  };
  // Gives back what a flight held once its thread is done.
  auto release = [&](Flight& f) {
    if (f.slot.worker_id.empty())
      --local_running;
    else
      registry_.release(f.slot.worker_id);
  };
  auto stop_all = [&] {
    for (auto& f : flights) f->context.TryCancel();
    for (auto& f : flights) {
      f->thread.join();
      release(*f);
    }
    flights.clear();
  };
  auto launch = [&](size_t i, std::optional<WorkerSlot> slot) {
    auto flight = std::make_unique<Flight>();
    Flight& f = *flight;
    f.index = i;
    f.attempt = ++attempts[i];
    f.start = std::chrono::steady_clock::now();
    auto finish = [&f, &changed, &mutex] {
      {
        std::lock_guard lock(mutex);
        f.finished = true;
      }
      changed.notify_all();
    };
    if (slot) {
      f.slot = *slot;
      rpc::attach_token(f.context, options_.token);
      auto stub = parapm::v1::WorkerService::NewStub(channels_.get(slot->address));
      f.thread = std::thread([&f, &requests, i, stub = std::move(stub), finish] {
        call_worker(f, *stub, requests[i]);
        finish();
      });
    } else {
      ++local_running;
      f.thread = std::thread([&f, &jobs, i, cancel, finish] {
        try {
          f.result = simplify_subset(jobs[i], {}, cancel);
        } catch (...) {
          f.status = rpc::status_of_current_exception();
        }
        finish();
      });
    }
    event(SubsetEvent::Kind::kStarted, f);
    flights.push_back(std::move(flight));
  };

  try {
    while (done < n) {
      if (cancel) cancel->check();
      // Harvest finished flights.
      for (auto it = flights.begin(); it != flights.end();) {
        if (!(*it)->finished) {
          // A worker that stopped beating will not answer: give its subset to another.
          Flight& f = **it;
          if (!f.slot.worker_id.empty() && !registry_.alive(f.slot.worker_id))
            f.context.TryCancel();
          ++it;
          continue;
        }
        // Out of the list before anything can throw: stop_all must not see it again.
        const std::unique_ptr<Flight> done_flight = std::move(*it);
        it = flights.erase(it);
        Flight& f = *done_flight;
        f.thread.join();
        release(f);
        if (f.status.ok() && !f.slot.worker_id.empty() &&
            f.result.state.metric != jobs[f.index].state.metric)
          f.status = {grpc::StatusCode::DATA_LOSS,
                      "the worker returned a state of metric '" + f.result.state.metric + "'"};
        if (f.status.ok()) {
          if (!f.slot.worker_id.empty()) {
            transport_.call_overhead_seconds +=
                std::max(0.0, f.call_seconds - f.result.wall_seconds);
            transport_.result_bytes += f.result_bytes;
            ++transport_.calls;
          }
          event(SubsetEvent::Kind::kDone, f);
          results[f.index] = std::move(f.result);
          ++done;
        } else if (f.slot.worker_id.empty() ||
                   f.status.error_code() == grpc::StatusCode::INVALID_ARGUMENT) {
          // In-process failures and jobs a worker calls malformed are not the worker's
          // fault: another attempt would fail the same way.
          throw Error(
              rpc::error_code_of(f.status.error_code()),
              "subset " + std::to_string(jobs[f.index].subset) + ": " + f.status.error_message());
        } else {
          spdlog::warn("job {}: subset {} of round {} failed on worker {} (attempt {}): {}",
                       options_.job_id, jobs[f.index].subset, jobs[f.index].round, f.slot.name,
                       f.attempt, f.status.error_message());
          if (f.status.error_code() == grpc::StatusCode::UNAVAILABLE)
            registry_.suspect(f.slot.worker_id);
          if (attempts[f.index] >= options_.max_attempts)
            throw Error(ErrorCode::kIo, "subset " + std::to_string(jobs[f.index].subset) +
                                            " failed " + std::to_string(attempts[f.index]) +
                                            " times; last: " + f.status.error_message());
          event(SubsetEvent::Kind::kRetry, f);
          last_worker[f.index] = f.slot.worker_id;
          pending.push_front(f.index);
        }
      }
      // Dispatch what waits.
      while (!pending.empty()) {
        const size_t i = pending.front();
        std::optional<WorkerSlot> slot = registry_.acquire({last_worker[i]});
        if (!slot) slot = registry_.acquire();
        if (slot) {
          pending.pop_front();
          launch(i, slot);
          continue;
        }
        if (registry_.live_count() == 0 && options_.local_threads > 0) {
          if (local_running >= options_.local_threads) break;
          if (!warned_waiting)
            spdlog::warn("job {}: no worker registered; running subsets in the coordinator",
                         options_.job_id);
          warned_waiting = true;
          pending.pop_front();
          launch(i, std::nullopt);
          continue;
        }
        if (registry_.live_count() == 0 && !warned_waiting) {
          spdlog::warn("job {}: waiting for a worker to register", options_.job_id);
          warned_waiting = true;
        }
        break;
      }
      std::unique_lock lock(mutex);
      changed.wait_for(lock, std::chrono::milliseconds(100), [&] {
        for (auto& f : flights)
          if (f->finished) return true;
        return false;
      });
    }
  } catch (...) {
    stop_all();
    throw;
  }
  return results;
}

}  // namespace parapm::service
