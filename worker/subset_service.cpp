#include "subset_service.h"

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include <spdlog/spdlog.h>

#include "parallel/held_state.h"
#include "parallel/job_codec.h"
#include "parallel/simplify_subset.h"
#include "rpc_server.h"
#include "util/clock.h"
#include "util/error.h"
#include "util/memory.h"
#include "util/progress.h"

namespace parapm::worker {
namespace {

// Records per stream message: ~1.5 MB at the records' usual size, well under the limits and
// large enough that the per-message overhead does not count.
constexpr size_t kRecordsPerBatch = 16384;
constexpr auto kProgressInterval = std::chrono::milliseconds(250);
constexpr auto kCancelPoll = std::chrono::milliseconds(20);
constexpr size_t kMaxBuildKey = 256;  // the coordinator's are a job id and a random id

// Passes the call's cancellation (the coordinator cancelled the job, or went away) to the
// engine within kCancelPoll, whatever the engine is doing; stops at once when destroyed (the
// subset's slot is not held while it sleeps).
class CancelWatcher {
 public:
  CancelWatcher(grpc::ServerContext& context, CancelToken& cancel)
      : thread_([this, &context, &cancel] {
          std::unique_lock lock(mutex_);
          while (!stopped_) {
            if (context.IsCancelled()) {
              cancel.cancel();
              return;
            }
            stop_.wait_for(lock, kCancelPoll);
          }
        }) {}
  ~CancelWatcher() {
    {
      std::lock_guard lock(mutex_);
      stopped_ = true;
    }
    stop_.notify_one();
    thread_.join();
  }
  CancelWatcher(const CancelWatcher&) = delete;
  CancelWatcher& operator=(const CancelWatcher&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable stop_;
  bool stopped_ = false;
  std::thread thread_;  // last: starts once the members above exist
};

}  // namespace

SubsetService::SubsetService(rpc::TokenCheck auth, unsigned slots, WorkerMetrics& metrics,
                             HeldStateCache& held)
    : auth_(std::move(auth)), slots_(std::max(1u, slots)), metrics_(metrics), held_(held) {}

namespace {

grpc::Status not_held(size_t items) {
  return {grpc::StatusCode::FAILED_PRECONDITION,
          "this worker does not hold the state of the " + std::to_string(items) +
              " items the job leaves out (it was restarted or dropped them): send them"};
}

}  // namespace

grpc::Status SubsetService::restore_held_state(const parapm::v1::SubsetRequest& request,
                                               const std::vector<uint32_t>& held, SubsetJob& job) {
  if (held.empty()) return grpc::Status::OK;
  // (the caller checked the build key; the decoder the indices against the state, and the
  // quadric state's vertices against the job)
  const std::string& build = request.build_key();
  if (job.state.metric == "quadric") {
    const QuadricState& state = job.state.quadric;
    std::vector<VertexId> global(held.size());
    for (size_t i = 0; i < held.size(); ++i) global[i] = job.global_vertex[state.vertices[held[i]]];
    std::vector<Quadric> quadrics;
    if (!held_.find(build, global, quadrics) ||
        quadrics_fingerprint(quadrics) != request.held_fingerprint())
      return not_held(held.size());
    put_back_held_quadrics(job.state.quadric, held, quadrics);
    return grpc::Status::OK;
  }
  EnergyState& state = job.state.energy;  // (with positions: only then does a job hold points)
  const size_t k = state.points.empty() ? 0 : state.point_values.size() / state.points.size();
  std::vector<uint32_t> ids(held.size());
  for (size_t i = 0; i < held.size(); ++i) ids[i] = state.points[held[i]].id;
  std::vector<HeldPoint> points;
  std::vector<float> values;
  if (!held_.find_points(build, ids, k, points, values)) return not_held(held.size());
  std::vector<uint64_t> fingerprints(held.size());
  for (size_t i = 0; i < held.size(); ++i)
    fingerprints[i] = point_fingerprint(points[i], values.data() + i * k, k);
  if (fingerprints_fingerprint(fingerprints) != request.held_fingerprint())
    return not_held(held.size());
  put_back_held_points(state, held, points, values);
  return grpc::Status::OK;
}

void SubsetService::record_outcome(const grpc::Status& status, double seconds,
                                   uint64_t bytes_sent) {
  metrics_.result_bytes.Increment(double(bytes_sent));
  const grpc::StatusCode code = status.error_code();
  const char* outcome =
      status.ok() ? "done"
      : code == grpc::StatusCode::CANCELLED || code == grpc::StatusCode::DEADLINE_EXCEEDED
          ? "cancelled"
          : "failed";
  metrics_.subsets.Add({{"outcome", outcome}}).Increment();
  if (status.ok()) metrics_.subset_seconds.Observe(seconds);
}

bool SubsetService::acquire_slot(grpc::ServerContext* context, JobTeam& team) {
  std::unique_lock lock(mutex_);
  while (busy_ >= slots_) {
    if (context->IsCancelled()) return false;
    slot_freed_.wait_for(lock, std::chrono::milliseconds(100));
  }
  ++busy_;
  ++running_;
  const unsigned share = slots_ / busy_;
  if (share > 1) team = {share, share, JobTeam::kDefaultMinItems};
  return true;
}

void SubsetService::release_slot() {
  {
    std::lock_guard lock(mutex_);
    --busy_;
    --running_;
  }
  slot_freed_.notify_one();
}

grpc::Status SubsetService::SimplifySubset(grpc::ServerContext* context,
                                           const parapm::v1::SubsetRequest* request,
                                           grpc::ServerWriter<parapm::v1::SubsetProgress>* writer) {
  const auto start = std::chrono::steady_clock::now();
  uint64_t bytes_sent = 0;
  const grpc::Status status = rpc::serve(auth_, context, [&]() -> grpc::Status {
    metrics_.job_bytes.Increment(double(request->job().size() + request->held_ids().size()));
    if (request->build_key().size() > kMaxBuildKey)
      return {grpc::StatusCode::INVALID_ARGUMENT,
              "build key over " + std::to_string(kMaxBuildKey) + " bytes"};
    const std::vector<uint32_t> held_ids =
        request->held_ids().empty()
            ? std::vector<uint32_t>{}
            : decode_increasing_ids(request->held_ids(), kNoId, "held state's ids");
    if (!held_ids.empty() && request->build_key().empty())
      return {grpc::StatusCode::INVALID_ARGUMENT, "held state named without a build key"};
    // (each held item decodes to more than its id's byte: no more than this worker holds)
    if (held_ids.size() > held_.item_bound(request->build_key())) return not_held(held_ids.size());
    SubsetJob job = decode_subset_job(request->job(), held_ids);
    if (grpc::Status held = restore_held_state(*request, held_ids, job); !held.ok()) return held;
    const std::string name = "job " + request->job_id() + " round " + std::to_string(job.round) +
                             " subset " + std::to_string(job.subset);
    const auto decoded = std::chrono::steady_clock::now();
    JobTeam team;
    if (!acquire_slot(context, team))
      return {grpc::StatusCode::CANCELLED, "cancelled while queued"};
    struct SlotGuard {
      SubsetService* service;
      ~SlotGuard() { service->release_slot(); }
    } guard{this};
    {
      parapm::v1::SubsetProgress begun;
      begun.mutable_begun()->set_queued_seconds(seconds_since(decoded));
      if (!writer->Write(begun))
        return grpc::Status(grpc::StatusCode::CANCELLED, "the coordinator went away");
    }

    CancelToken cancel;
    if (context->deadline() != std::chrono::system_clock::time_point::max()) {
      const auto left = context->deadline() - std::chrono::system_clock::now();
      cancel.set_deadline(std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(left));
    }
    const CancelWatcher watcher(*context, cancel);
    auto last_progress = std::chrono::steady_clock::now();
    bool peer_gone = false;
    // Called every 1024 collapses: now and then, reports.
    auto progress = [&](uint64_t done, uint64_t total) {
      if (peer_gone) {
        cancel.cancel();
        return;
      }
      const auto now = std::chrono::steady_clock::now();
      if (now - last_progress < kProgressInterval) return;
      last_progress = now;
      parapm::v1::SubsetProgress message;
      message.mutable_progress()->set_collapses(done);
      message.mutable_progress()->set_faces_to_remove(total);
      if (!writer->Write(message)) peer_gone = true;
    };
    spdlog::info("{}: started, {} faces", name, job.mesh.face_count());
    // A job of a build keeps its points (an energy job's: their positions and values, which
    // never change, and their distances at its end), or its free vertices' quadrics at its end
    // (a quadric job's): held_state.h.
    const bool keeps = !request->build_key().empty();
    if (keeps) held_.keep_points(request->build_key(), job.state.energy);
    QuadricState kept;
    SubsetResult result;
    try {
      result = simplify_subset(std::move(job), progress, &cancel, keeps ? &kept : nullptr, team);
    } catch (const Error& e) {
      if (e.code() == ErrorCode::kCancelled || e.code() == ErrorCode::kDeadlineExceeded)
        spdlog::info("{}: stopped ({}) after {:.3f} s", name, e.what(), seconds_since(start));
      else
        spdlog::warn("{}: failed: {}", name, e.what());
      throw;
    }

    if (keeps) {
      held_.keep(request->build_key(), kept);
      held_.update_points(request->build_key(), result.state.energy);
    }
    kept = QuadricState{};

    // The records, then the summary; a failed write means the coordinator is gone.
    parapm::v1::SubsetProgress message;
    for (size_t i = 0; i < result.records.size(); i += kRecordsPerBatch) {
      const size_t count = std::min(kRecordsPerBatch, result.records.size() - i);
      message.set_record_batch(encode_collapse_records(result.records.data() + i, count));
      bytes_sent += message.ByteSizeLong();
      if (!writer->Write(message))
        return grpc::Status(grpc::StatusCode::CANCELLED, "the coordinator went away");
    }
    message.set_summary(encode_subset_summary(result));
    bytes_sent += message.ByteSizeLong();
    if (!writer->Write(message))
      return grpc::Status(grpc::StatusCode::CANCELLED, "the coordinator went away");
    spdlog::info("{}: {} collapses in {:.3f} s ({:.3f} s CPU), {}", name, result.records.size(),
                 seconds_since(start), result.cpu_seconds, result.stats.stop_reason);
    return grpc::Status::OK;
  });
  record_outcome(status, seconds_since(start), bytes_sent);
  release_free_memory();  // the subset's memory, freed on this call's thread, back to the system
  return status;
}

}  // namespace parapm::worker
