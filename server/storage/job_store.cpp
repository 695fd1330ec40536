#include "storage/job_store.h"

#include <spdlog/spdlog.h>
#include <sqlite3.h>
#include <algorithm>
#include <cmath>
#include <limits>

#include "storage/job_schema.h"
#include "storage/sqlite.h"
#include "util/error.h"

namespace parapm::service {

namespace {

// Column lists shared by the statements and by the row readers below: a reader's column
// indices follow this order.
constexpr const char* kMeshColumns =
    "mesh_id, sha256, file_name, bytes, vertices, faces, created_unix_ms";
constexpr const char* kJobColumns =
    "job_id, mesh_id, options, status, failure_reason, pm_sha256, input_faces, base_faces, "
    "vsplits, seconds, attempts, created_unix_ms, updated_unix_ms";

// Every query reads these column lists and binds values only; the SQL text is constant.
std::string select_from(const char* columns, const char* rest) {
  return std::string("SELECT ") + columns + " " + rest;
}

MeshRecord read_mesh(const sqlite::Statement& row) {
  MeshRecord mesh;
  mesh.mesh_id = row.column_text(0);
  mesh.sha256 = row.column_text(1);
  mesh.file_name = row.column_text(2);
  mesh.bytes = row.column_uint64(3);
  mesh.vertices = row.column_uint64(4);
  mesh.faces = row.column_uint64(5);
  mesh.created_unix_ms = row.column_int64(6);
  return mesh;
}

JobRecord read_job(const sqlite::Statement& row, const std::filesystem::path& file) {
  JobRecord job;
  job.job_id = row.column_text(0);
  job.mesh_id = row.column_text(1);
  job.options = row.column_blob(2);
  const std::string status = row.column_text(3);
  const std::optional<JobStatus> parsed = parse_job_status(status);
  if (!parsed)
    throw Error(ErrorCode::kIo, "job store: job " + job.job_id + " has unknown status '" + status +
                                    "' (" + file.string() + ")");
  job.status = *parsed;
  job.failure_reason = row.column_text(4);
  job.pm_sha256 = row.column_text(5);
  job.input_faces = row.column_uint64(6);
  job.base_faces = row.column_uint64(7);
  job.vsplits = row.column_uint64(8);
  job.seconds = row.column_double(9);
  const uint64_t attempts = row.column_uint64(10);
  if (attempts > std::numeric_limits<uint32_t>::max())
    throw Error(ErrorCode::kIo, "job store: job " + job.job_id + " has " +
                                    std::to_string(attempts) + " attempts (" + file.string() + ")");
  job.attempts = static_cast<uint32_t>(attempts);
  job.created_unix_ms = row.column_int64(11);
  job.updated_unix_ms = row.column_int64(12);
  return job;
}

// Binds ?1..?13 in kJobColumns order.
void bind_job(sqlite::Statement& statement, const JobRecord& job) {
  if (job.job_id.empty()) throw_invalid("job store: a job needs a job_id");
  if (job.mesh_id.empty()) throw_invalid("job store: job " + job.job_id + " needs a mesh_id");
  // SQLite stores NaN as NULL, which the NOT NULL column would refuse with a vaguer message.
  if (std::isnan(job.seconds)) throw_invalid("job store: job " + job.job_id + " has NaN seconds");
  statement.bind_text(1, job.job_id)
      .bind_text(2, job.mesh_id)
      .bind_blob(3, job.options)
      .bind_text(4, to_string(job.status))
      .bind_text(5, job.failure_reason)
      .bind_text(6, job.pm_sha256)
      .bind_uint64(7, job.input_faces)
      .bind_uint64(8, job.base_faces)
      .bind_uint64(9, job.vsplits)
      .bind_double(10, job.seconds)
      .bind_uint64(11, job.attempts)
      .bind_int64(12, job.created_unix_ms)
      .bind_int64(13, job.updated_unix_ms);
}

std::vector<JobRecord> read_jobs(sqlite::Statement& statement, const std::filesystem::path& file) {
  std::vector<JobRecord> jobs;
  while (statement.step()) jobs.push_back(read_job(statement, file));
  return jobs;
}

void set_up_connection(sqlite::Database& db) {
  // Wait for a lock held by another connection (the sqlite3 shell, a backup) instead of
  // failing at once with SQLITE_BUSY.
  const int rc = sqlite3_busy_timeout(db.handle(), 5000);
  if (rc != SQLITE_OK) db.fail(rc, "setting busy_timeout");
  // The first statement reads the file header: a file that is not a database fails here.
  sqlite::Statement journal(db, "PRAGMA journal_mode = WAL",
                            "opening the database (PRAGMA journal_mode = WAL)");
  const std::string mode = journal.step() ? journal.column_text(0) : "";
  if (mode != "wal")
    throw Error(ErrorCode::kIo, "job store: " + db.file().string() +
                                    " refused WAL journal mode (got '" + mode + "')");
  db.exec("PRAGMA synchronous = NORMAL", "setting synchronous = NORMAL");
  db.exec("PRAGMA foreign_keys = ON", "enabling foreign keys");
}

}  // namespace

JobStore::JobStore(const std::filesystem::path& db_file)
    : db_(std::make_unique<sqlite::Database>(db_file)) {
  set_up_connection(*db_);
  migrate_job_schema(*db_);
  spdlog::info("job store: opened {}", db_file.string());
}

JobStore::~JobStore() = default;

// ---- meshes

void JobStore::add_mesh(const MeshRecord& mesh) {
  if (mesh.mesh_id.empty()) throw_invalid("job store: a mesh needs a mesh_id");
  std::lock_guard lock(mutex_);
  sqlite::Statement insert(*db_,
                           "INSERT INTO meshes(mesh_id, sha256, file_name, bytes, vertices, "
                           "faces, created_unix_ms) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
                           "adding mesh " + mesh.mesh_id);
  insert.bind_text(1, mesh.mesh_id)
      .bind_text(2, mesh.sha256)
      .bind_text(3, mesh.file_name)
      .bind_uint64(4, mesh.bytes)
      .bind_uint64(5, mesh.vertices)
      .bind_uint64(6, mesh.faces)
      .bind_int64(7, mesh.created_unix_ms);
  insert.run();
}

std::optional<MeshRecord> JobStore::find_mesh(const std::string& mesh_id) const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(*db_, select_from(kMeshColumns, "FROM meshes WHERE mesh_id = ?1"),
                          "finding mesh " + mesh_id);
  query.bind_text(1, mesh_id);
  if (!query.step()) return std::nullopt;
  return read_mesh(query);
}

std::optional<MeshRecord> JobStore::find_mesh_by_sha256(const std::string& sha) const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(
      *db_,
      select_from(kMeshColumns,
                  "FROM meshes WHERE sha256 = ?1 ORDER BY created_unix_ms, mesh_id LIMIT 1"),
      "finding the mesh with sha256 " + sha);
  query.bind_text(1, sha);
  if (!query.step()) return std::nullopt;
  return read_mesh(query);
}

// ---- jobs

void JobStore::add_job(const JobRecord& job) {
  std::lock_guard lock(mutex_);
  sqlite::Statement insert(*db_,
                           std::string("INSERT INTO jobs(") + kJobColumns +
                               ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13)",
                           "adding job " + job.job_id + " for mesh " + job.mesh_id);
  bind_job(insert, job);
  insert.run();
}

std::optional<JobRecord> JobStore::find_job(const std::string& job_id) const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(*db_, select_from(kJobColumns, "FROM jobs WHERE job_id = ?1"),
                          "finding job " + job_id);
  query.bind_text(1, job_id);
  if (!query.step()) return std::nullopt;
  return read_job(query, db_->file());
}

void JobStore::update_job(const JobRecord& job) {
  std::lock_guard lock(mutex_);
  update_job_locked(job);
}

uint64_t JobStore::end_job(const JobRecord& job, int64_t unix_ms, std::string_view terminal_event) {
  std::lock_guard lock(mutex_);
  sqlite::Transaction transaction(*db_, "ending job " + job.job_id);
  update_job_locked(job);
  const uint64_t seq = append_event_locked(job.job_id, unix_ms, terminal_event);
  transaction.commit();
  return seq;
}

void JobStore::update_job_locked(const JobRecord& job) {
  sqlite::Statement update(*db_,
                           "UPDATE jobs SET mesh_id = ?2, options = ?3, status = ?4, "
                           "failure_reason = ?5, pm_sha256 = ?6, input_faces = ?7, "
                           "base_faces = ?8, vsplits = ?9, seconds = ?10, attempts = ?11, "
                           "created_unix_ms = ?12, updated_unix_ms = ?13 WHERE job_id = ?1",
                           "updating job " + job.job_id);
  bind_job(update, job);
  update.run();
  if (db_->changes() == 0)
    throw Error(ErrorCode::kNotFound, "job store: updating job " + job.job_id + ": no such job");
}

std::vector<JobRecord> JobStore::list_jobs(size_t limit) const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(
      *db_, select_from(kJobColumns, "FROM jobs ORDER BY created_unix_ms DESC, job_id LIMIT ?1"),
      "listing jobs");
  const uint64_t max_limit = std::numeric_limits<int64_t>::max();
  query.bind_uint64(1, std::min<uint64_t>(limit, max_limit));
  return read_jobs(query, db_->file());
}

std::vector<JobRecord> JobStore::jobs_with_status(std::initializer_list<JobStatus> statuses) const {
  if (statuses.size() == 0) return {};
  // One constant statement with a slot per possible status; unused slots repeat the first
  // status, which changes nothing in an IN list.
  constexpr int kSlots = 5;
  std::vector<JobStatus> wanted(statuses);
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  std::lock_guard lock(mutex_);
  sqlite::Statement query(*db_,
                          select_from(kJobColumns,
                                      "FROM jobs WHERE status IN (?1, ?2, ?3, ?4, ?5) "
                                      "ORDER BY created_unix_ms, job_id"),
                          "listing jobs by status");
  for (int slot = 0; slot < kSlots; ++slot)
    query.bind_text(slot + 1, to_string(wanted[std::min<size_t>(slot, wanted.size() - 1)]));
  return read_jobs(query, db_->file());
}

// ---- events

uint64_t JobStore::append_event(const std::string& job_id, int64_t unix_ms,
                                std::string_view payload) {
  std::lock_guard lock(mutex_);
  return append_event_locked(job_id, unix_ms, payload);
}

uint64_t JobStore::append_event_locked(const std::string& job_id, int64_t unix_ms,
                                       std::string_view payload) {
  // One statement picks the next seq and inserts it, atomically: even a second process on
  // the same file could not take the same seq (the primary key would refuse it).
  sqlite::Statement insert(*db_,
                           "INSERT INTO events(job_id, seq, unix_ms, payload) "
                           "SELECT ?1, COALESCE(MAX(seq), 0) + 1, ?2, ?3 FROM events "
                           "WHERE job_id = ?1 RETURNING seq",
                           "appending an event to job " + job_id);
  insert.bind_text(1, job_id).bind_int64(2, unix_ms).bind_blob(3, payload);
  if (!insert.step()) throw_internal("job store: appending an event returned no seq");
  const uint64_t seq = insert.column_uint64(0);
  insert.run();  // finishes the statement, which commits the row
  return seq;
}

std::vector<EventRecord> JobStore::events(const std::string& job_id, uint64_t after_seq) const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(*db_,
                          "SELECT seq, unix_ms, payload FROM events "
                          "WHERE job_id = ?1 AND seq > ?2 ORDER BY seq",
                          "reading the events of job " + job_id);
  const uint64_t max_seq = std::numeric_limits<int64_t>::max();
  query.bind_text(1, job_id).bind_uint64(2, std::min(after_seq, max_seq));
  std::vector<EventRecord> events;
  while (query.step()) {
    EventRecord event;
    event.job_id = job_id;
    event.seq = query.column_uint64(0);
    event.unix_ms = query.column_int64(1);
    event.payload = query.column_blob(2);
    events.push_back(std::move(event));
  }
  return events;
}

// ---- deletion and retention

void JobStore::delete_job_locked(const std::string& job_id) {
  sqlite::Statement events(*db_, "DELETE FROM events WHERE job_id = ?1",
                           "deleting the events of job " + job_id);
  events.bind_text(1, job_id);
  events.run();
  sqlite::Statement job(*db_, "DELETE FROM jobs WHERE job_id = ?1", "deleting job " + job_id);
  job.bind_text(1, job_id);
  job.run();
}

namespace {

bool is_live(JobStatus status) {
  return status == JobStatus::kQueued || status == JobStatus::kRunning;
}

[[noreturn]] void refuse_live(const JobRecord& job) {
  throw Error(ErrorCode::kFailedPrecondition,
              "job " + job.job_id + " is " + to_string(job.status) + ": cancel it first");
}

}  // namespace

void JobStore::delete_job(const std::string& job_id) {
  std::lock_guard lock(mutex_);
  sqlite::Transaction transaction(*db_, "deleting job " + job_id);
  sqlite::Statement query(*db_, select_from(kJobColumns, "FROM jobs WHERE job_id = ?1"),
                          "finding job " + job_id);
  query.bind_text(1, job_id);
  if (!query.step()) throw Error(ErrorCode::kNotFound, "no job '" + job_id + "'");
  const JobRecord job = read_job(query, db_->file());
  if (is_live(job.status)) refuse_live(job);
  delete_job_locked(job_id);
  transaction.commit();
}

std::vector<JobRecord> JobStore::delete_mesh(const std::string& mesh_id) {
  std::lock_guard lock(mutex_);
  sqlite::Transaction transaction(*db_, "deleting mesh " + mesh_id);
  sqlite::Statement mesh(*db_, "SELECT mesh_id FROM meshes WHERE mesh_id = ?1",
                         "finding mesh " + mesh_id);
  mesh.bind_text(1, mesh_id);
  if (!mesh.step()) throw Error(ErrorCode::kNotFound, "no mesh '" + mesh_id + "'");
  sqlite::Statement query(*db_, select_from(kJobColumns, "FROM jobs WHERE mesh_id = ?1"),
                          "listing the jobs of mesh " + mesh_id);
  query.bind_text(1, mesh_id);
  std::vector<JobRecord> jobs = read_jobs(query, db_->file());
  for (const JobRecord& job : jobs)
    if (is_live(job.status)) refuse_live(job);
  for (const JobRecord& job : jobs) delete_job_locked(job.job_id);
  sqlite::Statement remove(*db_, "DELETE FROM meshes WHERE mesh_id = ?1",
                           "deleting mesh " + mesh_id);
  remove.bind_text(1, mesh_id);
  remove.run();
  transaction.commit();
  return jobs;
}

std::vector<MeshRecord> JobStore::list_meshes() const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(
      *db_, select_from(kMeshColumns, "FROM meshes ORDER BY created_unix_ms, mesh_id"),
      "listing meshes");
  std::vector<MeshRecord> meshes;
  while (query.step()) meshes.push_back(read_mesh(query));
  return meshes;
}

std::vector<JobRecord> JobStore::ended_jobs() const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(
      *db_,
      select_from(kJobColumns,
                  "FROM jobs WHERE status IN (?1, ?2, ?3) ORDER BY updated_unix_ms, job_id"),
      "listing ended jobs");
  query.bind_text(1, to_string(JobStatus::kDone))
      .bind_text(2, to_string(JobStatus::kFailed))
      .bind_text(3, to_string(JobStatus::kCancelled));
  return read_jobs(query, db_->file());
}

size_t JobStore::jobs_of_mesh(const std::string& mesh_id) const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(*db_, "SELECT COUNT(*) FROM jobs WHERE mesh_id = ?1",
                          "counting the jobs of mesh " + mesh_id);
  query.bind_text(1, mesh_id);
  return query.step() ? size_t(query.column_uint64(0)) : 0;
}

std::map<JobStatus, uint64_t> JobStore::job_counts() const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(*db_, "SELECT status, COUNT(*) FROM jobs GROUP BY status",
                          "counting the jobs by state");
  std::map<JobStatus, uint64_t> counts;
  while (query.step())
    if (const auto status = parse_job_status(query.column_text(0)))
      counts[*status] = query.column_uint64(1);
  return counts;
}

std::set<std::string> JobStore::referenced_blobs() const {
  std::lock_guard lock(mutex_);
  sqlite::Statement query(
      *db_, "SELECT sha256 FROM meshes UNION SELECT pm_sha256 FROM jobs WHERE pm_sha256 != ''",
      "listing the blobs rows refer to");
  std::set<std::string> shas;
  while (query.step()) shas.insert(query.column_text(0));
  return shas;
}

}  // namespace parapm::service
