// The coordinator's durable state: meshes, jobs and job events in one SQLite file,
// DIR/parapm.db. Everything a restart needs is here, so a restarted coordinator loses nothing:
// it re-queues the jobs that were queued or running (jobs_with_status) and clients resume
// their event streams by seq.
//
// Durability: WAL journal with synchronous=NORMAL. A committed row survives a process crash;
// a power cut may lose the last few commits, never corrupt the file. Blobs are fsynced by
// BlobStore::Writer::commit(); callers commit a blob before they write the row that names it,
// so a row never refers to a missing blob.
//
// Thread safety: every member may be called from any thread; one mutex serialises them over
// one connection (the coordinator calls it from many gRPC threads, and each call is short).
// Errors: parapm::Error; kNotFound for a row that names a missing mesh or job or an update of
// a missing job, kInvalidInput for a duplicate id or an unstorable value, kIo for the rest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "storage/ids.h"
#include "storage/records.h"

namespace parapm::service {

namespace sqlite {
class Database;
}

class JobStore {
 public:
  // Opens or creates the file and brings its schema up to date. Throws kIo for a file that
  // is not a SQLite database, is corrupt, or was written by a newer build.
  explicit JobStore(const std::filesystem::path& db_file);
  ~JobStore();
  JobStore(const JobStore&) = delete;
  JobStore& operator=(const JobStore&) = delete;

  void add_mesh(const MeshRecord& mesh);
  std::optional<MeshRecord> find_mesh(const std::string& mesh_id) const;
  // The oldest mesh with these bytes, to answer a repeated upload without storing it again.
  std::optional<MeshRecord> find_mesh_by_sha256(const std::string& sha) const;

  void add_job(const JobRecord& job);  // kNotFound when job.mesh_id is not a stored mesh
  std::optional<JobRecord> find_job(const std::string& job_id) const;
  void update_job(const JobRecord& job);  // by job_id, every column; kNotFound when absent
  // Newest first: created_unix_ms descending, ties by job_id ascending. At most `limit`.
  std::vector<JobRecord> list_jobs(size_t limit) const;
  // Oldest first (created_unix_ms, then job_id): the order a restart re-queues them in.
  std::vector<JobRecord> jobs_with_status(std::initializer_list<JobStatus> statuses) const;

  // Stores an event and returns its seq: 1 for a job's first event, then +1 each time, even
  // across restarts and concurrent callers. kNotFound when the job does not exist.
  uint64_t append_event(const std::string& job_id, int64_t unix_ms, std::string_view payload);
  // The job's events with seq > after_seq, ascending (after_seq 0: all of them).
  std::vector<EventRecord> events(const std::string& job_id, uint64_t after_seq) const;
  // update_job and append_event in one transaction: a job's final state and its terminal
  // event (finished, failed, cancelled), so that no reader sees one without the other (a
  // watcher that finds the job ended must find its last event too). Returns the event's seq.
  uint64_t end_job(const JobRecord& job, int64_t unix_ms, std::string_view terminal_event);

  // Deletion, each in one transaction. A job that is queued or running is never deleted:
  // kFailedPrecondition (cancel it first), checked in the same transaction.
  // The job and its events; kNotFound when absent.
  void delete_job(const std::string& job_id);
  // The mesh, its jobs and their events; kNotFound when absent. Returns the jobs deleted.
  std::vector<JobRecord> delete_mesh(const std::string& mesh_id);
  // Every mesh, oldest first (created_unix_ms, then mesh_id).
  std::vector<MeshRecord> list_meshes() const;
  // Jobs that ended (done, failed or cancelled), oldest first by updated_unix_ms.
  std::vector<JobRecord> ended_jobs() const;
  size_t jobs_of_mesh(const std::string& mesh_id) const;
  // How many jobs are stored in each state (states without a job are absent).
  std::map<JobStatus, uint64_t> job_counts() const;
  // The blob hashes the rows name: every mesh's sha256 and every job's pm_sha256.
  std::set<std::string> referenced_blobs() const;

 private:
  void update_job_locked(const JobRecord& job);
  void delete_job_locked(const std::string& job_id);
  uint64_t append_event_locked(const std::string& job_id, int64_t unix_ms,
                               std::string_view payload);

  mutable std::mutex mutex_;
  std::unique_ptr<sqlite::Database> db_;  // guarded by mutex_
};

}  // namespace parapm::service
