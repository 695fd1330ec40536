// The coordinator's core, which the MeshService and Coordination bridges call: uploads become
// validated meshes in the blob store, submissions become jobs in SQLite, a scheduler runs
// queued jobs (the engine's parallel build, its subsets sent to workers by RemoteRunner), and
// every step of a job is an event, stored and woken up for watchers.
//
// Its boundary: the API's protobuf messages (parapm.v1 Job, JobEvent, JobOptions) are its
// domain types, plain data it stores and returns as they are (an event is stored as its
// serialized message); it is a gRPC client of the workers (RemoteRunner, WorkerChannels, the
// credentials in its config). It is no part of the gRPC server: no ServerContext and no
// grpc::Status here; it throws parapm::Error, and the bridges convert requests, replies and
// errors (rpc::serve).
//
// Durability: a mesh's or PM's blob is written and fsync'd before the row naming it; a job's
// row changes state before its event is appended. On start, jobs left queued or running by a
// previous process are queued again and re-run from their mesh (the build is deterministic,
// so the PM is the one the first run would have made).
#pragma once

#include <condition_variable>
#include <deque>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <semaphore>
#include <string>
#include <thread>
#include <vector>

#include "coordinator_metrics.h"
#include "io/mesh_io.h"
#include "parapm.pb.h"
#include "pm_library.h"
#include "remote_runner.h"
#include "storage/blob_store.h"
#include "storage/job_store.h"
#include "upload_handoff.h"
#include "util/progress.h"
#include "worker_registry.h"

namespace parapm::service {

struct CoordinatorConfig {
  std::filesystem::path data_dir;
  uint64_t max_upload_bytes = uint64_t(2) << 30;  // as sent (compressed, for a .gz)
  uint64_t max_mesh_bytes = uint64_t(4) << 30;    // a mesh file once inflated
  uint32_t default_parallelism = 4;
  unsigned max_running_jobs = 2;
  // Subsets run in the coordinator when no worker is registered (0: wait for workers).
  unsigned local_threads = 0;
  std::chrono::milliseconds heartbeat{1000};
  std::string worker_token;  // sent on calls to workers
  std::shared_ptr<grpc::ChannelCredentials> worker_credentials;
  // Retention, applied at start and every retention_check: jobs that ended longer ago than
  // retain_for are deleted, and meshes older than that with no job left (0: kept forever);
  // while the blobs hold more than retain_bytes, the oldest ended jobs, then the oldest
  // meshes without a job (uploaded more than an hour ago), are deleted (0: no bound).
  std::chrono::milliseconds retain_for{0};
  uint64_t retain_bytes = 0;
  std::chrono::milliseconds retention_check{std::chrono::minutes(10)};
  // How long the last upload's parsed mesh waits for a job to take it (UploadHandoff).
  std::chrono::milliseconds upload_handoff{std::chrono::seconds(30)};
};

// What a deletion removed: rows, and the blobs no row refers to any more.
struct DeleteResult {
  uint64_t jobs = 0, meshes = 0, blobs = 0, bytes = 0;
};

// An upload in progress: bytes gathered up to the size limit.
class Upload {
 public:
  Upload(std::string file_name, uint64_t max_bytes);
  // Throws Error(kResourceExhausted) past the limit.
  void add(std::string_view bytes);
  const std::string& file_name() const { return file_name_; }
  uint64_t size() const { return bytes_.size(); }

 private:
  friend class Coordinator;
  std::string file_name_;
  uint64_t max_bytes_;
  std::string bytes_;
};

struct UploadResult {
  MeshRecord mesh;
  std::string repairs;  // "" when the repair step changed nothing
};

class Coordinator {
 public:
  explicit Coordinator(CoordinatorConfig config);
  ~Coordinator();  // stop(), then waits for the schedulers
  // Starts no job any more and cancels the running ones, which stay "running" in the
  // database, to be re-run by the next start. Called on SIGTERM before the server drains its
  // calls: a job still computing while the server waits (up to 2 s) for open event streams
  // would finish instead of being left to the next start. Idempotent.
  void stop();
  Coordinator(const Coordinator&) = delete;
  Coordinator& operator=(const Coordinator&) = delete;

  WorkerRegistry& workers() { return registry_; }
  CoordinatorMetrics& metrics() { return metrics_; }
  // Sets the metrics' gauges of state (jobs by state, queue depth, registered workers) to
  // what they are now: called before each scrape.
  void refresh_metrics();
  const CoordinatorConfig& config() const { return config_; }

  Upload begin_upload(const std::string& file_name) const;
  // Parses and repairs the mesh (Error(kInvalidInput) with the parser's message when it is
  // not one), stores its bytes. The same bytes again give the same mesh.
  UploadResult finish_upload(Upload upload);

  // Throws kNotFound for an unknown mesh, kInvalidInput for bad options.
  parapm::v1::Job submit(const std::string& mesh_id, const parapm::v1::JobOptions& options);
  parapm::v1::Job job(const std::string& job_id);  // kNotFound
  std::vector<parapm::v1::Job> jobs(size_t limit);
  // Queued: cancelled at once. Running: its build stops at its next check (workers' calls
  // are cancelled). Finished: unchanged. Returns the job as it is after the call.
  parapm::v1::Job cancel(const std::string& job_id);

  // Events with seq > after_seq; waits up to `wait` for one when there is none yet.
  std::vector<parapm::v1::JobEvent> events(const std::string& job_id, uint64_t after_seq,
                                           std::chrono::milliseconds wait);

  // Deletes an ended job (kFailedPrecondition while queued or running, kNotFound) and the
  // blobs no row refers to any more.
  DeleteResult delete_job(const std::string& job_id);
  // Deletes a mesh with its ended jobs (kFailedPrecondition while one is queued or running).
  DeleteResult delete_mesh(const std::string& mesh_id);
  // Applies the retention of the config once (the retention thread calls it).
  DeleteResult apply_retention();

  // A done job's PM, its bytes checked against their hash (kFailedPrecondition when the job
  // is not done; kDataLoss when its stored PM is corrupt).
  std::shared_ptr<const LoadedPm> pm(const std::string& job_id);

 private:
  struct Running {
    CancelToken cancel;
    uint64_t progress_done = 0, progress_total = 0;
  };

  void scheduler_loop();
  void retention_loop();
  // Removes the blobs no row names (committed more than a minute ago: a blob is written
  // before its row).
  DeleteResult collect_garbage();
  // Builds a job the scheduler took off the queue and listed in running_ (`running`).
  void run_job(const std::string& job_id, Running& running);
  void execute(JobRecord& record, Running& running, parapm::v1::JobEvent::Transport& transport);
  void emit(const std::string& job_id, parapm::v1::JobEvent event);
  // Stores the job's final state and its terminal event together (JobStore::end_job).
  void end_job(const JobRecord& record, parapm::v1::JobEvent terminal);
  parapm::v1::Job to_proto(const JobRecord& record);
  JobRecord load_job(const std::string& job_id);  // kNotFound
  ReadLimits read_limits() const;                 // for uploads and stored meshes
  JobRecord done_job(const std::string& job_id);  // kFailedPrecondition unless done

  CoordinatorConfig config_;
  CoordinatorMetrics metrics_;
  BlobStore blobs_;
  JobStore store_;
  WorkerRegistry registry_;
  WorkerChannels channels_;
  PmLibrary library_;
  UploadHandoff handoff_;

  std::mutex upload_mutex_;  // the sha256 lookup and the insert of a new mesh
  // Uploads parsed at once: each holds its inflated file and mesh, up to max_mesh_bytes and
  // more, so this bounds their memory whatever the number of clients.
  std::counting_semaphore<> parse_slots_{2};
  std::mutex mutex_;
  std::condition_variable queue_changed_;
  std::condition_variable events_changed_;
  std::condition_variable stop_requested_;  // wakes the retention thread
  std::deque<std::string> queue_;
  std::map<std::string, std::shared_ptr<Running>> running_;
  bool stopping_ = false;
  std::vector<std::thread> schedulers_;
  std::thread retention_;  // only when a retention is configured
};

}  // namespace parapm::service
