#include "coordinator.h"

#include <chrono>
#include <sstream>

#include <spdlog/spdlog.h>

#include "io/mesh_io.h"
#include "job_options.h"
#include "mesh/repair.h"
#include "parallel/parallel_build.h"
#include "storage/ids.h"
#include "util/chunked_loops.h"
#include "util/clock.h"
#include "util/error.h"
#include "util/memory.h"

namespace parapm::service {
namespace {

parapm::v1::JobState state_of(JobStatus status) {
  switch (status) {
    case JobStatus::kQueued:
      return parapm::v1::QUEUED;
    case JobStatus::kRunning:
      return parapm::v1::RUNNING;
    case JobStatus::kDone:
      return parapm::v1::DONE;
    case JobStatus::kFailed:
      return parapm::v1::FAILED;
    case JobStatus::kCancelled:
      return parapm::v1::CANCELLED;
  }
  return parapm::v1::JOB_STATE_UNSPECIFIED;
}

// A mesh file's bytes read and repaired, in chunks on the hardware's threads (the same mesh
// as on one thread).
std::shared_ptr<const RepairedMesh> parse_mesh(const std::string& bytes, const std::string& name,
                                               const ReadLimits& limits) {
  ChunkedLoops loops(std::max(1u, std::thread::hardware_concurrency()), 0);
  RepairOptions options;
  options.loops = &loops;
  return std::make_shared<const RepairedMesh>(
      repair_mesh(read_mesh_from_memory(bytes, name, nullptr, limits, &loops), options));
}

std::string repairs_text(const RepairReport& r) {
  std::ostringstream text;
  auto item = [&](uint64_t count, const char* what) {
    if (count == 0) return;
    if (text.tellp() > 0) text << ", ";
    text << count << ' ' << what;
  };
  item(r.degenerate_faces_removed, "degenerate faces removed");
  item(r.duplicate_faces_removed, "duplicate faces removed");
  item(r.unreferenced_vertices_removed, "unreferenced vertices removed");
  item(r.nonmanifold_edges, "non-manifold edges cut");
  item(r.vertex_copies_added, "vertex copies made at non-manifold vertices");
  return text.str();
}

// The event as stored: its job and the time it happened.
void stamp(parapm::v1::JobEvent& event, const std::string& job_id) {
  event.set_job_id(job_id);
  event.set_unix_ms(unix_ms_now());
}

}  // namespace

Upload::Upload(std::string file_name, uint64_t max_bytes)
    : file_name_(std::move(file_name)), max_bytes_(max_bytes) {}

void Upload::add(std::string_view bytes) {
  if (bytes_.size() + bytes.size() > max_bytes_)
    throw Error(ErrorCode::kResourceExhausted, "upload larger than this coordinator accepts (" +
                                                   std::to_string(max_bytes_) +
                                                   " bytes; --max-upload-mb)");
  bytes_.append(bytes);
}

Coordinator::Coordinator(CoordinatorConfig config)
    : config_(std::move(config)),
      blobs_(config_.data_dir),
      store_(config_.data_dir / "parapm.db"),
      registry_(config_.heartbeat),
      channels_(config_.worker_credentials ? config_.worker_credentials
                                           : grpc::InsecureChannelCredentials()),
      handoff_(config_.upload_handoff) {
  // What a previous process left unfinished runs again, oldest first.
  for (JobRecord& job : store_.jobs_with_status({JobStatus::kQueued, JobStatus::kRunning})) {
    if (job.status == JobStatus::kRunning) {
      spdlog::info("job {}: was running when the coordinator stopped; queued again", job.job_id);
      job.status = JobStatus::kQueued;
      job.updated_unix_ms = unix_ms_now();
      store_.update_job(job);
      parapm::v1::JobEvent event;
      event.mutable_queued();
      emit(job.job_id, event);
    }
    queue_.push_back(job.job_id);
  }
  for (unsigned i = 0; i < std::max(1u, config_.max_running_jobs); ++i)
    schedulers_.emplace_back([this] { scheduler_loop(); });
  if (config_.retain_for.count() > 0 || config_.retain_bytes > 0)
    retention_ = std::thread([this] { retention_loop(); });
  spdlog::info("coordinator data in {}: {} jobs queued", config_.data_dir.string(), queue_.size());
}

Coordinator::~Coordinator() {
  stop();
  for (std::thread& t : schedulers_) t.join();
  if (retention_.joinable()) retention_.join();
}

void Coordinator::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (auto& [id, running] : running_) running->cancel.cancel();
  }
  queue_changed_.notify_all();
  events_changed_.notify_all();
  stop_requested_.notify_all();
}

ReadLimits Coordinator::read_limits() const {
  ReadLimits limits;
  limits.max_bytes = config_.max_mesh_bytes;
  return limits;
}

Upload Coordinator::begin_upload(const std::string& file_name) const {
  if (file_name.empty() || file_name.size() > 255)
    throw_invalid(
        "the first upload chunk must name the file (1 to 255 characters), e.g. bunny.ply");
  return Upload(file_name, config_.max_upload_bytes);
}

UploadResult Coordinator::finish_upload(Upload upload) {
  if (upload.bytes_.empty()) throw_invalid(upload.file_name_ + ": the upload is empty");
  const std::string sha = sha256_hex(upload.bytes_);
  UploadResult result;
  // Validate whatever the bytes (a repeated upload of a bad file is as bad).
  parse_slots_.acquire();
  struct Release {
    std::counting_semaphore<>& slots;
    ~Release() { slots.release(); }
  } release{parse_slots_};
  const std::shared_ptr<const RepairedMesh> parsed = [&] {
    // An upload's parse frees hundreds of MB on a large mesh into glibc's per-thread arenas:
    // given back to the system after it, whether it succeeded or not, so that an idle
    // coordinator's memory falls back near where it started.
    struct GiveBack {
      ~GiveBack() { release_free_memory(); }
    } give_back;
    return parse_mesh(upload.bytes_, upload.file_name_, read_limits());
  }();
  const RepairedMesh& repaired = *parsed;
  if (repaired.mesh.face_count() == 0)
    throw_invalid(upload.file_name_ + ": no faces left after repair");
  result.repairs = repairs_text(repaired.report);
  // One upload at a time from here: the same bytes uploaded twice at once get one mesh id.
  std::lock_guard lock(upload_mutex_);
  if (std::optional<MeshRecord> known = store_.find_mesh_by_sha256(sha)) {
    result.mesh = *known;
    spdlog::info("upload {} ({} bytes) is mesh {} already", upload.file_name_, upload.bytes_.size(),
                 known->mesh_id);
    handoff_.put(result.mesh.sha256, parsed);
    return result;
  }
  result.mesh.sha256 = blobs_.put(upload.bytes_);
  result.mesh.mesh_id = new_id("mesh-");
  result.mesh.file_name = upload.file_name_;
  result.mesh.bytes = upload.bytes_.size();
  result.mesh.vertices = repaired.mesh.vertex_count();
  result.mesh.faces = repaired.mesh.face_count();
  result.mesh.created_unix_ms = unix_ms_now();
  store_.add_mesh(result.mesh);
  spdlog::info("mesh {} uploaded: {} ({} bytes, {} vertices, {} faces)", result.mesh.mesh_id,
               result.mesh.file_name, result.mesh.bytes, result.mesh.vertices, result.mesh.faces);
  handoff_.put(result.mesh.sha256, parsed);
  return result;
}

parapm::v1::Job Coordinator::submit(const std::string& mesh_id,
                                    const parapm::v1::JobOptions& options) {
  const std::optional<MeshRecord> mesh = store_.find_mesh(mesh_id);
  if (!mesh) throw Error(ErrorCode::kNotFound, "no mesh '" + mesh_id + "' (upload it first)");
  // p is pinned at submission (the PM depends on it): the coordinator's default, or as many
  // as the mesh can use when that is fewer.
  const uint32_t most_p = most_useful_parallelism(mesh->faces);
  parapm::v1::JobOptions pinned = options;
  if (!pinned.has_parallelism())
    pinned.set_parallelism(std::min(config_.default_parallelism, most_p));
  const JobSpec spec = job_spec_of(pinned, config_.default_parallelism);
  if (spec.parallel.subsets > most_p)
    throw_invalid("job options: parallelism " + std::to_string(spec.parallel.subsets) +
                  " on a mesh of " + std::to_string(mesh->faces) +
                  " faces makes subsets of fewer than " + std::to_string(kLeastSubsetFaces) +
                  " faces, mostly border; this mesh can use at most " + std::to_string(most_p));
  JobRecord record;
  record.job_id = new_id("job-");
  record.mesh_id = mesh_id;
  record.options = pinned.SerializeAsString();
  record.status = JobStatus::kQueued;
  record.input_faces = mesh->faces;
  record.created_unix_ms = record.updated_unix_ms = unix_ms_now();
  store_.add_job(record);
  parapm::v1::JobEvent event;
  event.mutable_queued();
  emit(record.job_id, event);
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(record.job_id);
  }
  queue_changed_.notify_one();
  spdlog::info("job {} queued: mesh {} ({} faces), p = {}, metric {}", record.job_id, mesh_id,
               mesh->faces, spec.parallel.subsets, spec.simplify.metric);
  return to_proto(record);
}

JobRecord Coordinator::load_job(const std::string& job_id) {
  std::optional<JobRecord> record = store_.find_job(job_id);
  if (!record) throw Error(ErrorCode::kNotFound, "no job '" + job_id + "'");
  return *record;
}

parapm::v1::Job Coordinator::to_proto(const JobRecord& r) {
  parapm::v1::Job job;
  job.set_job_id(r.job_id);
  job.set_mesh_id(r.mesh_id);
  job.mutable_options()->ParseFromString(r.options);
  job.set_state(state_of(r.status));
  job.set_failure_reason(r.failure_reason);
  job.set_input_faces(r.input_faces);
  job.set_base_faces(r.base_faces);
  job.set_vsplits(r.vsplits);
  job.set_seconds(r.seconds);
  job.set_created_unix_ms(r.created_unix_ms);
  job.set_updated_unix_ms(r.updated_unix_ms);
  job.set_attempts(r.attempts);
  job.set_pm_sha256(r.pm_sha256);
  if (!r.pm_sha256.empty() && blobs_.contains(r.pm_sha256))
    job.set_pm_bytes(blobs_.size_of(r.pm_sha256));
  std::lock_guard lock(mutex_);
  if (const auto it = running_.find(r.job_id);
      it != running_.end() && r.status == JobStatus::kRunning) {
    job.set_progress_done(it->second->progress_done);
    job.set_progress_total(it->second->progress_total);
  }
  return job;
}

parapm::v1::Job Coordinator::job(const std::string& job_id) { return to_proto(load_job(job_id)); }

std::vector<parapm::v1::Job> Coordinator::jobs(size_t limit) {
  std::vector<parapm::v1::Job> out;
  for (const JobRecord& r : store_.list_jobs(limit)) out.push_back(to_proto(r));
  return out;
}

parapm::v1::Job Coordinator::cancel(const std::string& job_id) {
  JobRecord record = load_job(job_id);
  bool cancelled_queued = false;
  {
    std::lock_guard lock(mutex_);
    if (const auto it = running_.find(job_id); it != running_.end()) {
      it->second->cancel.cancel();
      spdlog::info("job {}: cancel requested while running", job_id);
    } else if (record.status == JobStatus::kQueued) {
      std::erase(queue_, job_id);  // (not there: the job waits for the next start)
      cancelled_queued = true;
    }
  }
  if (cancelled_queued) {
    record.status = JobStatus::kCancelled;
    record.updated_unix_ms = unix_ms_now();
    parapm::v1::JobEvent event;
    event.mutable_cancelled();
    metrics_.jobs_ended.Add({{"state", "cancelled"}}).Increment();
    end_job(record, event);
    spdlog::info("job {}: cancelled while queued", job_id);
  }
  return to_proto(load_job(job_id));
}

void Coordinator::emit(const std::string& job_id, parapm::v1::JobEvent event) {
  stamp(event, job_id);
  store_.append_event(job_id, event.unix_ms(), event.SerializeAsString());
  events_changed_.notify_all();
}

void Coordinator::end_job(const JobRecord& record, parapm::v1::JobEvent terminal) {
  stamp(terminal, record.job_id);
  store_.end_job(record, terminal.unix_ms(), terminal.SerializeAsString());
  events_changed_.notify_all();
}

std::vector<parapm::v1::JobEvent> Coordinator::events(const std::string& job_id, uint64_t after_seq,
                                                      std::chrono::milliseconds wait) {
  load_job(job_id);  // kNotFound
  auto fetch = [&] {
    std::vector<parapm::v1::JobEvent> out;
    for (const EventRecord& r : store_.events(job_id, after_seq)) {
      parapm::v1::JobEvent event;
      if (!event.ParseFromString(r.payload))
        throw Error(ErrorCode::kInternal, "job " + job_id + ": stored event " +
                                              std::to_string(r.seq) + " does not parse");
      event.set_seq(r.seq);
      out.push_back(std::move(event));
    }
    return out;
  };
  std::vector<parapm::v1::JobEvent> out = fetch();
  if (!out.empty() || wait.count() == 0) return out;
  {
    std::unique_lock lock(mutex_);
    events_changed_.wait_for(lock, wait);
  }
  return fetch();
}

DeleteResult Coordinator::collect_garbage() {
  const BlobStore::Removed removed =
      blobs_.remove_unreferenced(store_.referenced_blobs(), std::chrono::seconds(60));
  DeleteResult result;
  result.blobs = removed.blobs;
  result.bytes = removed.bytes;
  return result;
}

DeleteResult Coordinator::delete_job(const std::string& job_id) {
  store_.delete_job(job_id);
  DeleteResult result = collect_garbage();
  result.jobs = 1;
  spdlog::info("job {} deleted ({} blobs, {} bytes freed)", job_id, result.blobs, result.bytes);
  return result;
}

DeleteResult Coordinator::delete_mesh(const std::string& mesh_id) {
  std::vector<JobRecord> jobs;
  {
    // Not while an upload of the same bytes is answering with this mesh.
    std::lock_guard lock(upload_mutex_);
    jobs = store_.delete_mesh(mesh_id);
  }
  DeleteResult result = collect_garbage();
  result.meshes = 1;
  result.jobs = jobs.size();
  spdlog::info("mesh {} deleted with {} jobs ({} blobs, {} bytes freed)", mesh_id, jobs.size(),
               result.blobs, result.bytes);
  return result;
}

DeleteResult Coordinator::apply_retention() {
  DeleteResult result;
  const int64_t now = unix_ms_now();
  auto drop_job = [&](const JobRecord& job) {
    try {
      store_.delete_job(job.job_id);
      ++result.jobs;
    } catch (const Error& e) {
      if (e.code() != ErrorCode::kNotFound && e.code() != ErrorCode::kFailedPrecondition) throw;
    }
  };
  auto drop_mesh_without_jobs = [&](const MeshRecord& mesh) {
    std::lock_guard lock(upload_mutex_);
    if (store_.jobs_of_mesh(mesh.mesh_id) > 0) return false;
    store_.delete_mesh(mesh.mesh_id);
    ++result.meshes;
    return true;
  };
  if (config_.retain_for.count() > 0) {
    const int64_t before = now - config_.retain_for.count();
    for (const JobRecord& job : store_.ended_jobs())
      if (job.updated_unix_ms < before) drop_job(job);
    for (const MeshRecord& mesh : store_.list_meshes())
      if (mesh.created_unix_ms < before) drop_mesh_without_jobs(mesh);
  }
  DeleteResult freed = collect_garbage();
  if (config_.retain_bytes > 0) {
    // Oldest first, one at a time, until the blobs fit (a blob is freed once no row names it).
    for (const JobRecord& job : store_.ended_jobs()) {
      if (blobs_.stored_bytes() <= config_.retain_bytes) break;
      drop_job(job);
      const DeleteResult more = collect_garbage();
      freed.blobs += more.blobs;
      freed.bytes += more.bytes;
    }
    // A mesh uploaded in the last hour is spared: its client may not have submitted yet.
    const int64_t fresh = now - int64_t(3600) * 1000;
    for (const MeshRecord& mesh : store_.list_meshes()) {
      if (blobs_.stored_bytes() <= config_.retain_bytes) break;
      if (mesh.created_unix_ms > fresh || !drop_mesh_without_jobs(mesh)) continue;
      const DeleteResult more = collect_garbage();
      freed.blobs += more.blobs;
      freed.bytes += more.bytes;
    }
  }
  result.blobs = freed.blobs;
  result.bytes = freed.bytes;
  if (result.jobs + result.meshes + result.blobs > 0)
    spdlog::info("retention: {} jobs, {} meshes and {} blobs ({} bytes) deleted", result.jobs,
                 result.meshes, result.blobs, result.bytes);
  return result;
}

void Coordinator::retention_loop() {
  std::unique_lock lock(mutex_);
  do {
    lock.unlock();
    try {
      apply_retention();
    } catch (const std::exception& e) {
      spdlog::error("retention: {}", e.what());
    }
    lock.lock();
  } while (!stop_requested_.wait_for(lock, config_.retention_check, [this] { return stopping_; }));
}

JobRecord Coordinator::done_job(const std::string& job_id) {
  JobRecord record = load_job(job_id);
  if (record.status != JobStatus::kDone)
    throw Error(ErrorCode::kFailedPrecondition,
                "job " + job_id + " is " + to_string(record.status) + ", not done: no PM yet");
  return record;
}

std::shared_ptr<const LoadedPm> Coordinator::pm(const std::string& job_id) {
  JobRecord record = done_job(job_id);
  try {
    return library_.get(record.pm_sha256, blobs_);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kDataLoss) throw;
    // Never served again: the job shows why, and the same mesh submitted again rebuilds it.
    record.status = JobStatus::kFailed;
    record.failure_reason = std::string(e.what()) + "; submit the mesh again to rebuild it";
    record.updated_unix_ms = unix_ms_now();
    parapm::v1::JobEvent event;
    event.mutable_failed()->set_reason(record.failure_reason);
    end_job(record, event);
    spdlog::error("job {}: marked failed: {}", job_id, record.failure_reason);
    throw;
  }
}

void Coordinator::scheduler_loop() {
  while (true) {
    std::string job_id;
    std::shared_ptr<Running> running;
    {
      std::unique_lock lock(mutex_);
      queue_changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job_id = queue_.front();
      queue_.pop_front();
      // Off the queue and among the running in one step: a cancel finds the job in one or the
      // other, never between them.
      running = std::make_shared<Running>();
      running_[job_id] = running;
    }
    try {
      run_job(job_id, *running);
    } catch (const std::exception& e) {
      // Only the store failing gets here: the job stays as the database has it.
      spdlog::error("job {}: {}", job_id, e.what());
    }
    {
      std::lock_guard lock(mutex_);
      running_.erase(job_id);
    }
    release_free_memory();  // the job's mesh, state and PM, as after an upload's parse
  }
}

void Coordinator::refresh_metrics() {
  const std::map<JobStatus, uint64_t> counts = store_.job_counts();
  for (JobStatus status : {JobStatus::kQueued, JobStatus::kRunning, JobStatus::kDone,
                           JobStatus::kFailed, JobStatus::kCancelled}) {
    const auto found = counts.find(status);
    metrics_.jobs.Add({{"state", to_string(status)}})
        .Set(found == counts.end() ? 0.0 : double(found->second));
  }
  {
    std::lock_guard lock(mutex_);
    metrics_.queue_depth.Set(double(queue_.size()));
  }
  metrics_.workers_registered.Set(double(registry_.live_count()));
}

void Coordinator::run_job(const std::string& job_id, Running& running) {
  JobRecord record = load_job(job_id);
  if (record.status != JobStatus::kQueued) return;  // cancelled meanwhile
  {
    std::lock_guard lock(mutex_);
    if (stopping_) return;  // still queued: the next start runs it
  }
  record.status = JobStatus::kRunning;
  ++record.attempts;
  record.updated_unix_ms = unix_ms_now();
  store_.update_job(record);
  const auto start = std::chrono::steady_clock::now();
  try {
    parapm::v1::JobEvent::Transport transport;
    execute(record, running, transport);
    record.status = JobStatus::kDone;
    record.seconds = seconds_since(start);
    record.updated_unix_ms = unix_ms_now();
    parapm::v1::JobEvent event;
    auto* done = event.mutable_finished();
    done->set_base_faces(record.base_faces);
    done->set_vsplits(record.vsplits);
    done->set_seconds(record.seconds);
    done->set_pm_sha256(record.pm_sha256);
    *done->mutable_transport() = transport;
    // Counted before the end is published: whoever sees the job ended scrapes it counted.
    metrics_.jobs_ended.Add({{"state", "done"}}).Increment();
    metrics_.job_build_seconds.Observe(record.seconds);
    end_job(record, event);
    spdlog::info("job {} done: {} -> {} faces, {} vsplits in {:.3f} s", job_id, record.input_faces,
                 record.base_faces, record.vsplits, record.seconds);
  } catch (const Error& e) {
    bool shutting_down;
    {
      std::lock_guard lock(mutex_);
      shutting_down = stopping_;
    }
    if (e.code() == ErrorCode::kCancelled && shutting_down) {
      // Left "running": the next start re-runs it.
      spdlog::info("job {}: interrupted by shutdown; it re-runs at the next start", job_id);
    } else {
      parapm::v1::JobEvent event;
      if (e.code() == ErrorCode::kCancelled) {
        record.status = JobStatus::kCancelled;
        event.mutable_cancelled();
        spdlog::info("job {} cancelled", job_id);
      } else {
        record.status = JobStatus::kFailed;
        record.failure_reason = e.what();
        event.mutable_failed()->set_reason(e.what());
        spdlog::warn("job {} failed: {}", job_id, e.what());
      }
      record.seconds = seconds_since(start);
      record.updated_unix_ms = unix_ms_now();
      metrics_.jobs_ended.Add({{"state", to_string(record.status)}}).Increment();
      end_job(record, event);
    }
  } catch (const std::exception& e) {
    record.status = JobStatus::kFailed;
    record.failure_reason = std::string("internal error: ") + e.what();
    record.updated_unix_ms = unix_ms_now();
    parapm::v1::JobEvent event;
    event.mutable_failed()->set_reason(record.failure_reason);
    metrics_.jobs_ended.Add({{"state", "failed"}}).Increment();
    end_job(record, event);
    spdlog::error("job {} failed: {}", job_id, record.failure_reason);
  }
}

void Coordinator::execute(JobRecord& record, Running& running,
                          parapm::v1::JobEvent::Transport& transport) {
  const std::string& job_id = record.job_id;
  parapm::v1::JobOptions options;
  options.ParseFromString(record.options);
  const JobSpec spec = job_spec_of(options, config_.default_parallelism);
  const std::optional<MeshRecord> mesh_record = store_.find_mesh(record.mesh_id);
  if (!mesh_record) throw Error(ErrorCode::kNotFound, "mesh " + record.mesh_id + " is gone");
  auto t = std::chrono::steady_clock::now();
  std::shared_ptr<const RepairedMesh> parsed = handoff_.take(mesh_record->sha256);
  const bool from_upload = parsed != nullptr;
  if (!parsed)
    parsed = parse_mesh(blobs_.read(mesh_record->sha256), mesh_record->file_name, read_limits());
  const RepairedMesh& repaired = *parsed;
  transport.set_read_seconds(seconds_since(t));
  record.input_faces = repaired.mesh.face_count();
  {
    parapm::v1::JobEvent event;
    auto* started = event.mutable_started();
    started->set_attempt(record.attempts);
    started->set_input_faces(record.input_faces);
    started->set_target_faces(target_face_count(record.input_faces, spec.simplify));
    emit(job_id, event);
  }
  spdlog::info(
      "job {} started (attempt {}): {} faces, p = {}, {} scheduled rounds, metric {}; the mesh {}",
      job_id, record.attempts, record.input_faces, spec.parallel.subsets,
      scheduled_rounds(spec.parallel), spec.simplify.metric,
      from_upload ? "as parsed at its upload" : "read from its blob");

  RemoteOptions remote;
  remote.job_id = job_id;
  remote.token = config_.worker_token;
  remote.local_threads = config_.local_threads;
  RemoteRunner runner(registry_, channels_, remote, [&](const SubsetEvent& e) {
    parapm::v1::JobEvent event;
    if (e.kind == SubsetEvent::Kind::kRetry) metrics_.subsets_retried.Increment();
    if (e.kind == SubsetEvent::Kind::kStarted) {
      metrics_.subsets_dispatched.Increment();
      auto* s = event.mutable_subset_started();
      s->set_round(e.round);
      s->set_subset(e.subset);
      s->set_worker(e.worker);
      s->set_attempt(e.attempt);
    } else if (e.kind == SubsetEvent::Kind::kDone) {
      auto* d = event.mutable_subset_done();
      d->set_round(e.round);
      d->set_subset(e.subset);
      d->set_worker(e.worker);
      d->set_seconds(e.seconds);
      d->set_cpu_seconds(e.cpu_seconds);
      d->set_transfer_seconds(e.transfer_seconds);
      d->set_collapses(e.collapses);
    } else {
      return;  // a retry shows as the next "started" with its attempt number
    }
    emit(job_id, event);
  });
  // The bytes moved count whether the build ends well or not.
  struct CountMoved {
    const RemoteRunner& runner;
    CoordinatorMetrics& metrics;
    ~CountMoved() {
      metrics.subset_job_bytes.Increment(double(runner.transport().job_bytes));
      metrics.subset_result_bytes.Increment(double(runner.transport().result_bytes));
    }
  } count_moved{runner, metrics_};
  ParallelEvents events;
  events.partitioned = [&](uint32_t round, uint32_t subsets, uint64_t faces) {
    parapm::v1::JobEvent event;
    auto* p = event.mutable_partitioned();
    p->set_round(round);
    p->set_subsets(subsets);
    p->set_faces(faces);
    emit(job_id, event);
  };
  events.merged = [&](const RoundStats& round) {
    parapm::v1::JobEvent event;
    auto* m = event.mutable_merged();
    m->set_round(round.round);
    m->set_seconds(round.merge_seconds);
    m->set_faces(round.faces_after);
    emit(job_id, event);
  };
  auto last_progress = std::chrono::steady_clock::now();
  auto progress = [&](uint64_t done, uint64_t total) {
    {
      std::lock_guard lock(mutex_);
      running.progress_done = done;
      running.progress_total = total;
    }
    if (seconds_since(last_progress) < 1 && done < total) return;
    last_progress = std::chrono::steady_clock::now();
    parapm::v1::JobEvent event;
    event.mutable_progress()->set_done(done);
    event.mutable_progress()->set_total(total);
    emit(job_id, event);
  };
  ParallelStats stats;
  ProgressiveMesh pm = build_progressive_mesh_parallel(
      repaired, spec.simplify, spec.parallel, &stats, progress, &running.cancel, &runner, events);
  t = std::chrono::steady_clock::now();
  record.base_faces = pm.base.face_count();
  record.vsplits = pm.splits.size();
  ChunkedLoops write_loops(spec.parallel.subsets, spec.parallel.threads);
  std::shared_ptr<LoadedPm> stored = written_pm(std::move(pm), write_loops);
  record.pm_sha256 = blobs_.put(stored->bytes);
  library_.put(record.pm_sha256, std::move(stored));  // its first download reads no blob
  transport.set_store_seconds(seconds_since(t));
  const TransportStats& moved = runner.transport();
  transport.set_encode_seconds(moved.encode_seconds);
  transport.set_call_overhead_seconds(moved.call_overhead_seconds);
  transport.set_job_bytes(moved.job_bytes);
  transport.set_result_bytes(moved.result_bytes);
  transport.set_calls(moved.calls);
  transport.set_held_items(moved.held_items);
  transport.set_sent_items(moved.sent_items);
  spdlog::info(
      "job {} transport: {} calls, jobs {:.1f} MB encoded in {:.3f} s ({} items of state left out, "
      "held by their workers; {} sent), results {:.1f} MB, call overhead {:.3f} s in all; read "
      "{:.3f} s, store {:.3f} s",
      job_id, moved.calls, double(moved.job_bytes) / 1e6, moved.encode_seconds, moved.held_items,
      moved.sent_items, double(moved.result_bytes) / 1e6, moved.call_overhead_seconds,
      transport.read_seconds(), transport.store_seconds());
}

}  // namespace parapm::service
