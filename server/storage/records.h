// The rows of the job database, as plain values. The service's own messages (job options,
// progress events) are stored as opaque bytes, so this layer needs no protobuf.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace parapm::service {

// An uploaded mesh. Its bytes are the blob `sha256`; several uploads of the same bytes are
// separate meshes sharing one blob.
struct MeshRecord {
  std::string mesh_id, sha256, file_name;
  uint64_t bytes = 0, vertices = 0, faces = 0;
  int64_t created_unix_ms = 0;
};

// A job's life: kQueued -> kRunning -> kDone | kFailed | kCancelled. A restart puts kQueued
// and kRunning jobs back in the queue (see JobStore::jobs_with_status).
enum class JobStatus { kQueued, kRunning, kDone, kFailed, kCancelled };

// Stored as text ("queued", "running", "done", "failed", "cancelled") so that the database
// reads plainly in the sqlite3 shell.
const char* to_string(JobStatus status);
std::optional<JobStatus> parse_job_status(std::string_view text);

struct JobRecord {
  std::string job_id, mesh_id;
  std::string options;  // opaque bytes (the service stores a serialized protobuf)
  JobStatus status = JobStatus::kQueued;
  std::string failure_reason;  // empty unless kFailed
  std::string pm_sha256;       // the built Progressive Mesh's blob; empty until kDone
  uint64_t input_faces = 0, base_faces = 0, vsplits = 0;
  double seconds = 0;     // wall time of the last run
  uint32_t attempts = 0;  // how many times it was started (a restart re-runs it)
  int64_t created_unix_ms = 0, updated_unix_ms = 0;
};

// One progress or state event of a job, in the order it happened. seq is 1-based and
// increases by one per event of the same job, so a client resumes a stream with "after seq".
struct EventRecord {
  std::string job_id;
  uint64_t seq = 0;
  int64_t unix_ms = 0;
  std::string payload;  // opaque bytes
};

}  // namespace parapm::service
