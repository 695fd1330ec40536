#include "remote_runner.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <set>
#include <thread>

#include <spdlog/spdlog.h>

#include "parallel/held_state.h"
#include "parallel/job_codec.h"
#include "parallel/job_state.h"
#include "parallel/simplify_subset.h"
#include "parapm.grpc.pb.h"
#include "rpc_security.h"
#include "rpc_status.h"
#include "storage/ids.h"
#include "util/clock.h"
#include "util/error.h"
#include "util/job_pool.h"

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
  // Set when the request made for the job leaves out state another worker holds: this
  // flight sends the job whole, encoded on its own thread.
  std::optional<parapm::v1::SubsetRequest> whole;
  uint64_t job_bytes = 0;   // what the call sent
  uint64_t held_items = 0;  // quadrics or points it left out
  // With a build key: what the worker holds after the job (holdable items: id, fingerprint).
  std::vector<std::pair<uint32_t, uint64_t>> kept;
  std::chrono::steady_clock::time_point start;
  grpc::ClientContext context;
  std::thread thread;
  std::atomic<bool> begun{false};  // the worker took it into a slot (or it runs in-process)
  bool announced = false;          // its "started" event sent (the dispatching thread's)
  std::atomic<bool> finished{false};
  grpc::Status status;
  SubsetResult result;
  double call_seconds = 0;    // wall, at the coordinator
  double queued_seconds = 0;  // at the worker, decoded, waiting for a slot (queued ahead)
  uint64_t result_bytes = 0;
};

// The call's time beyond the worker's own, not counting its wait for a slot there.
double transfer_seconds(const Flight& f) {
  return std::max(0.0, f.call_seconds - f.result.wall_seconds - f.queued_seconds);
}

// Reads the worker's stream into flight.result; the status says how it ended. A worker that
// sends what does not decode is treated like one that failed (its subset goes elsewhere).
// `on_sent` runs once the request is sent (while the worker works; it must not throw),
// `on_begun` when the worker says the subset holds a slot.
void call_worker(Flight& flight, parapm::v1::WorkerService::Stub& stub,
                 const parapm::v1::SubsetRequest& request, const std::function<void()>& on_sent,
                 const std::function<void()>& on_begun) {
  const auto start = std::chrono::steady_clock::now();
  auto reader = stub.SimplifySubset(&flight.context, request);
  on_sent();
  parapm::v1::SubsetProgress message;
  bool summary = false;
  std::string broken;
  while (reader->Read(&message)) {
    try {
      if (message.has_begun()) {
        // Clamped: the worker's figure only splits the call's own time.
        flight.queued_seconds =
            std::clamp(message.begun().queued_seconds(), 0.0, seconds_since(start));
        on_begun();
      } else if (message.has_record_batch()) {
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
      on_event_(std::move(on_event)) {
  build_key_ = options_.job_id + "/" + new_id("build-");
}

namespace {

// What the worker of a quadric job keeps at its end (held_state.h), as fingerprints: the
// job's initial free quadrics (initial_free_quadrics) followed through its records, the
// arithmetic of the worker's module. Error(kInvalidInput) when a record names a vertex that is
// not a free one of the job.
std::vector<std::pair<uint32_t, uint64_t>> kept_fingerprints(QuadricState quadrics,
                                                             const SubsetResult& result) {
  follow_records(quadrics, result.records);
  std::vector<std::pair<uint32_t, uint64_t>> kept(quadrics.vertices.size());
  for (size_t i = 0; i < kept.size(); ++i)
    kept[i] = {quadrics.vertices[i], quadric_fingerprint(quadrics.quadrics[i])};
  return kept;
}

}  // namespace

// One run(): a round's subsets from their requests to their results. Its flights' threads
// write only their own Flight; everything else is the dispatching thread's.
class RemoteRunner::Dispatch {
 public:
  Dispatch(RemoteRunner& runner, std::vector<SubsetJob>& jobs, const CancelToken* cancel)
      : runner_(runner),
        jobs_(jobs),
        cancel_(cancel),
        results_(jobs.size()),
        attempts_(jobs.size(), 0),
        last_worker_(jobs.size()),
        holder_(jobs.size()) {}

  std::vector<SubsetResult> run() {
    encode_requests();
    for (size_t i = 0; i < jobs_.size(); ++i) pending_.push_back(i);
    try {
      for (;;) {
        if (cancel_) cancel_->check();
        harvest();
        if (done_ == jobs_.size()) break;
        dispatch_pending();
        wait_for_a_flight();
      }
    } catch (...) {
      stop_all();
      throw;
    }
    return std::move(results_);
  }

 private:
  bool keeps_state(const SubsetJob& job) const {
    return job.options.metric == "quadric" || job.options.metric == "energy";
  }

  // The request of subset i as any worker takes it: the job whole.
  parapm::v1::SubsetRequest whole_request(size_t i) const {
    parapm::v1::SubsetRequest request;
    request.set_job_id(runner_.options_.job_id);
    request.set_round(jobs_[i].round);
    request.set_subset(jobs_[i].subset);
    if (keeps_state(jobs_[i])) request.set_build_key(runner_.build_key_);
    request.set_job(encode_subset_job(jobs_[i]));
    return request;
  }

  // Side by side, one job per hardware thread (each request is its own). A job goes without
  // what its planned worker holds (holder_[i]; HeldStateLedger::plan_round): those quadrics or
  // points as their ids alone.
  void encode_requests() {
    const auto encode_start = std::chrono::steady_clock::now();
    std::map<std::string, uint32_t> slots = runner_.registry_.live_slots_by_worker();
    for (const std::string& id : runner_.distrusted_) slots.erase(id);
    items_.assign(jobs_.size(), {});
    run_jobs(jobs_.size(), 0, [&](size_t i) {
      if (keeps_state(jobs_[i])) items_[i] = holdable_items(jobs_[i]);
    });
    const std::vector<HeldStateLedger::Plan> plans = runner_.held_.plan_round(items_, slots);
    requests_.resize(jobs_.size());
    held_count_.assign(jobs_.size(), 0);
    run_jobs(jobs_.size(), 0, [&](size_t i) {
      const SubsetJob& job = jobs_[i];
      const HeldStateLedger::Plan& plan = plans[i];
      if (plan.count == 0 || !keeps_state(job)) {
        requests_[i] = whole_request(i);
        return;
      }
      parapm::v1::SubsetRequest& request = requests_[i];
      request.set_job_id(runner_.options_.job_id);
      request.set_round(job.round);
      request.set_subset(job.subset);
      request.set_build_key(runner_.build_key_);
      // The held items, by their indices in the state's order.
      std::vector<uint32_t> indices;
      std::vector<uint64_t> fingerprints;
      for (uint32_t k = 0; k < plan.held.size(); ++k)
        if (plan.held[k]) {
          indices.push_back(k);
          fingerprints.push_back(items_[i][k].second);
        }
      request.set_held_ids(encode_increasing_ids(indices));
      request.set_held_fingerprint(fingerprints_fingerprint(fingerprints));
      request.set_job(encode_subset_job(job, job.state, indices));
      holder_[i] = plan.worker;
      held_count_[i] = plan.count;
    });
    runner_.transport_.encode_seconds += seconds_since(encode_start);
  }

  void event(SubsetEvent::Kind kind, const Flight& f) const {
    if (!runner_.on_event_) return;
    SubsetEvent e;
    e.kind = kind;
    e.round = jobs_[f.index].round;
    e.subset = jobs_[f.index].subset;
    e.worker = f.slot.worker_id.empty() ? "coordinator" : f.slot.name;
    e.attempt = f.attempt;
    if (kind == SubsetEvent::Kind::kDone) {
      e.seconds = f.result.wall_seconds;
      e.cpu_seconds = f.result.cpu_seconds;
      if (!f.slot.worker_id.empty()) e.transfer_seconds = transfer_seconds(f);
      e.collapses = f.result.records.size();
    } else if (kind == SubsetEvent::Kind::kRetry) {
      e.reason = f.status.error_message();
    }
    runner_.on_event_(e);
  }

  // Gives back what a flight held once its thread is done.
  void release(Flight& f) {
    if (f.slot.worker_id.empty())
      --local_running_;
    else
      runner_.registry_.release(f.slot.worker_id);
  }

  void stop_all() {
    for (auto& f : flights_) f->context.TryCancel();
    for (auto& f : flights_) {
      f->thread.join();
      release(*f);
    }
    flights_.clear();
  }

  // Subset i on `slot`'s worker, or in-process without one, on a thread of its own. A job
  // whose request leaves out state goes whole to another worker than its holder.
  void launch(size_t i, std::optional<WorkerSlot> slot) {
    auto flight = std::make_unique<Flight>();
    Flight& f = *flight;
    f.index = i;
    f.attempt = ++attempts_[i];
    f.start = std::chrono::steady_clock::now();
    auto mark = [this](std::atomic<bool>& flag) {
      {
        std::lock_guard lock(mutex_);
        flag = true;
      }
      changed_.notify_all();
    };
    if (slot) {
      f.slot = *slot;
      const bool whole = !requests_[i].held_ids().empty() && holder_[i] != slot->worker_id;
      rpc::attach_token(f.context, runner_.options_.token);
      auto stub = parapm::v1::WorkerService::NewStub(runner_.channels_.get(slot->address));
      f.thread = std::thread([this, &f, i, whole, stub = std::move(stub), mark] {
        try {
          if (whole) f.whole = whole_request(i);
          const parapm::v1::SubsetRequest& request = f.whole ? *f.whole : requests_[i];
          f.job_bytes = request.job().size() + request.held_ids().size();
          if (!f.whole) f.held_items = held_count_[i];
          // What the worker will keep: a quadric job's quadrics from these (found while it
          // works), followed through its records; an energy job's points as sent, with the
          // distances its result returns.
          const bool keeps = !request.build_key().empty();
          const bool quadric = jobs_[i].options.metric == "quadric";
          QuadricState initial;
          std::string failed;
          auto find_kept = [&] {
            if (!keeps) return;
            try {
              if (quadric) initial = initial_free_quadrics(jobs_[i]);
            } catch (const std::exception& e) {
              failed = e.what();
            }
          };
          call_worker(f, *stub, request, find_kept, [&] { mark(f.begun); });
          if (!failed.empty()) throw Error(ErrorCode::kInternal, failed);
          if (f.status.ok() && keeps)
            f.kept = quadric ? kept_fingerprints(std::move(initial), f.result)
                             : held_items_after(jobs_[i], f.result.state.energy);
        } catch (const std::exception& e) {
          f.status = {grpc::StatusCode::DATA_LOSS, e.what()};
        }
        mark(f.finished);
      });
    } else {
      ++local_running_;
      f.begun = true;
      f.thread = std::thread([&f, job = &jobs_[i], cancel = cancel_, mark] {
        try {
          f.result = simplify_subset(*job, {}, cancel);
        } catch (...) {
          f.status = rpc::status_of_current_exception();
        }
        mark(f.finished);
      });
    }
    flights_.push_back(std::move(flight));
  }

  // "Started" when the subset holds a slot, not when its call is sent (it may wait at the
  // worker, queued ahead); at the latest with its result (a worker that does not say).
  void announce(Flight& f) {
    if (f.announced) return;
    f.announced = true;
    event(SubsetEvent::Kind::kStarted, f);
  }

  // Announces the flights that began; takes the finished flights' outcomes; cancels the calls
  // of workers that stopped beating (they will not answer: their subsets go to another).
  void harvest() {
    for (auto it = flights_.begin(); it != flights_.end();) {
      Flight& f = **it;
      if (f.begun) announce(f);
      if (!f.finished) {
        if (!f.slot.worker_id.empty() && !runner_.registry_.alive(f.slot.worker_id))
          f.context.TryCancel();
        ++it;
        continue;
      }
      // Out of the list before anything can throw: stop_all must not see it again.
      const std::unique_ptr<Flight> done_flight = std::move(*it);
      it = flights_.erase(it);
      done_flight->thread.join();
      release(*done_flight);
      if (done_flight->status.ok()) announce(*done_flight);
      take_outcome(*done_flight);
    }
  }

  // A finished flight: its result, or a retry elsewhere, or the job's failure (Error).
  void take_outcome(Flight& f) {
    const SubsetJob& job = jobs_[f.index];
    if (!f.slot.worker_id.empty()) runner_.transport_.job_bytes += f.job_bytes;
    if (f.status.ok() && !f.slot.worker_id.empty() &&
        f.result.state.metric != returned_state_metric(job))
      f.status = {grpc::StatusCode::DATA_LOSS, "the worker returned a state of metric '" +
                                                   f.result.state.metric + "', expected '" +
                                                   returned_state_metric(job) + "'"};
    if (f.status.ok()) {
      if (!f.slot.worker_id.empty()) {
        TransportStats& transport = runner_.transport_;
        transport.call_overhead_seconds += transfer_seconds(f);
        transport.result_bytes += f.result_bytes;
        ++transport.calls;
        transport.held_items += f.held_items;
        transport.sent_items += items_[f.index].size() - f.held_items;
      }
      if (!f.kept.empty()) runner_.held_.record(f.slot.worker_id, f.kept);
      event(SubsetEvent::Kind::kDone, f);
      results_[f.index] = std::move(f.result);
      ++done_;
      return;
    }
    // In-process failures and jobs a worker calls malformed are not the worker's fault:
    // another attempt would fail the same way.
    if (f.slot.worker_id.empty() || f.status.error_code() == grpc::StatusCode::INVALID_ARGUMENT)
      throw Error(rpc::error_code_of(f.status.error_code()),
                  "subset " + std::to_string(job.subset) + ": " + f.status.error_message());
    if (f.status.error_code() == grpc::StatusCode::FAILED_PRECONDITION &&
        holder_[f.index] == f.slot.worker_id) {
      // The worker no longer holds what the job left out: the job goes whole, and no job of
      // this build leaves anything out for that worker again. Not the subset's failure.
      spdlog::info("job {}: worker {} lacks the state subset {} of round {} left out: {}",
                   runner_.options_.job_id, f.slot.name, job.subset, job.round,
                   f.status.error_message());
      runner_.distrusted_.insert(f.slot.worker_id);
      holder_[f.index].clear();
      --attempts_[f.index];
      pending_.push_front(f.index);
      return;
    }
    spdlog::warn("job {}: subset {} of round {} failed on worker {} (attempt {}): {}",
                 runner_.options_.job_id, job.subset, job.round, f.slot.name, f.attempt,
                 f.status.error_message());
    if (f.status.error_code() == grpc::StatusCode::UNAVAILABLE)
      runner_.registry_.suspect(f.slot.worker_id);
    if (attempts_[f.index] >= runner_.options_.max_attempts)
      throw Error(ErrorCode::kIo, "subset " + std::to_string(job.subset) + " failed " +
                                      std::to_string(attempts_[f.index]) +
                                      " times; last: " + f.status.error_message());
    event(SubsetEvent::Kind::kRetry, f);
    last_worker_[f.index] = f.slot.worker_id;
    pending_.push_front(f.index);
  }

  // The first waiting subset whose held state's holder can take it now, launched there.
  bool dispatch_to_holders() {
    WorkerRegistry& registry = runner_.registry_;
    const bool queue_ahead = pending_.size() > registry.live_slots();
    for (auto it = pending_.begin(); it != pending_.end(); ++it) {
      const size_t i = *it;
      if (holder_[i].empty() || holder_[i] == last_worker_[i]) continue;
      if (std::optional<WorkerSlot> slot = registry.acquire_on(holder_[i], queue_ahead)) {
        pending_.erase(it);
        launch(i, slot);
        return true;
      }
    }
    return false;
  }

  // Launches what waits on the free workers: first each on the worker holding its state,
  // then on any (another than the one it failed on, where possible), or in-process when no
  // worker is registered and the options allow it.
  void dispatch_pending() {
    const RemoteOptions& options = runner_.options_;
    WorkerRegistry& registry = runner_.registry_;
    while (!pending_.empty()) {
      if (dispatch_to_holders()) continue;
      const size_t i = pending_.front();
      std::optional<WorkerSlot> slot = registry.acquire({last_worker_[i]});
      if (!slot) slot = registry.acquire();
      // Queued ahead only while more subsets wait than the live workers have slots: the
      // round's last subsets go to free slots, not behind another subset.
      if (!slot && pending_.size() > registry.live_slots())
        slot = registry.acquire({last_worker_[i]}, true);
      if (slot) {
        pending_.pop_front();
        launch(i, slot);
        continue;
      }
      if (registry.live_count() == 0 && options.local_threads > 0) {
        if (local_running_ >= options.local_threads) break;
        if (!warned_waiting_)
          spdlog::warn("job {}: no worker registered; running subsets in the coordinator",
                       options.job_id);
        warned_waiting_ = true;
        pending_.pop_front();
        launch(i, std::nullopt);
        continue;
      }
      if (registry.live_count() == 0 && !warned_waiting_) {
        spdlog::warn("job {}: waiting for a worker to register", options.job_id);
        warned_waiting_ = true;
      }
      break;
    }
  }

  // Until a flight begins or finishes, or 100 ms (heartbeats, cancellation and new workers
  // are checked between waits).
  void wait_for_a_flight() {
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, std::chrono::milliseconds(100), [&] {
      for (auto& f : flights_)
        if (f->finished || (f->begun && !f->announced)) return true;
      return false;
    });
  }

  RemoteRunner& runner_;
  std::vector<SubsetJob>& jobs_;
  const CancelToken* cancel_;
  std::vector<parapm::v1::SubsetRequest> requests_;
  std::vector<SubsetResult> results_;
  std::deque<size_t> pending_;            // subsets waiting for a worker, retries first
  std::vector<uint32_t> attempts_;        // per subset
  std::vector<std::string> last_worker_;  // per subset: the worker it last failed on
  // Per subset: the worker its request was made for (it leaves out the state that worker
  // holds); empty: none, or that worker lost them (the job goes whole).
  std::vector<std::string> holder_;
  std::vector<uint64_t> held_count_;  // per subset: the items its request leaves out
  // Per subset: its holdable items (holdable_items), found once.
  std::vector<std::vector<std::pair<uint32_t, uint64_t>>> items_;
  std::vector<std::unique_ptr<Flight>> flights_;
  std::mutex mutex_;  // guards the flights' `finished` with changed_
  std::condition_variable changed_;
  size_t done_ = 0;
  unsigned local_running_ = 0;
  bool warned_waiting_ = false;
};

std::vector<SubsetResult> RemoteRunner::run(std::vector<SubsetJob>& jobs,
                                            const CancelToken* cancel) {
  return Dispatch(*this, jobs, cancel).run();
}

}  // namespace parapm::service
