#include "storage/job_schema.h"

#include <spdlog/spdlog.h>

#include "util/error.h"

namespace parapm::service {

namespace {

// kMigrations[v] moves a file from version v to v + 1 and ends by setting that version.
// Never edit a migration once released: add a new one.
//
// status is plain text without a CHECK: adding a state later must not need a table rebuild;
// the reader refuses an unknown status instead. Unsigned counts are INTEGER (signed 64-bit);
// the binding layer refuses values that do not fit.
constexpr const char* kMigrations[kJobSchemaVersion] = {
    R"sql(
CREATE TABLE meshes(
  mesh_id         TEXT PRIMARY KEY NOT NULL,
  sha256          TEXT NOT NULL,
  file_name       TEXT NOT NULL,
  bytes           INTEGER NOT NULL,
  vertices        INTEGER NOT NULL,
  faces           INTEGER NOT NULL,
  created_unix_ms INTEGER NOT NULL
);
CREATE INDEX meshes_by_sha256 ON meshes(sha256, created_unix_ms, mesh_id);

CREATE TABLE jobs(
  job_id          TEXT PRIMARY KEY NOT NULL,
  mesh_id         TEXT NOT NULL REFERENCES meshes(mesh_id),
  options         BLOB NOT NULL,
  status          TEXT NOT NULL,
  failure_reason  TEXT NOT NULL,
  pm_sha256       TEXT NOT NULL,
  input_faces     INTEGER NOT NULL,
  base_faces      INTEGER NOT NULL,
  vsplits         INTEGER NOT NULL,
  seconds         REAL NOT NULL,
  attempts        INTEGER NOT NULL,
  created_unix_ms INTEGER NOT NULL,
  updated_unix_ms INTEGER NOT NULL
);
CREATE INDEX jobs_by_created ON jobs(created_unix_ms, job_id);
CREATE INDEX jobs_by_status ON jobs(status, created_unix_ms, job_id);

-- WITHOUT ROWID: the (job_id, seq) key is the table's order, so reading a job's events after
-- a seq is one range scan.
CREATE TABLE events(
  job_id  TEXT NOT NULL REFERENCES jobs(job_id),
  seq     INTEGER NOT NULL,
  unix_ms INTEGER NOT NULL,
  payload BLOB NOT NULL,
  PRIMARY KEY(job_id, seq)
) WITHOUT ROWID;

PRAGMA user_version = 1;
)sql",
};

int read_user_version(sqlite::Database& db) {
  sqlite::Statement query(db, "PRAGMA user_version", "reading the schema version");
  if (!query.step()) throw Error(ErrorCode::kIo, "job store: PRAGMA user_version returned no row");
  return static_cast<int>(query.column_int64(0));
}

}  // namespace

void migrate_job_schema(sqlite::Database& db) {
  int version = read_user_version(db);
  if (version > kJobSchemaVersion || version < 0)
    throw Error(ErrorCode::kIo, "job store: " + db.file().string() + " has schema version " +
                                    std::to_string(version) + ", this build knows up to " +
                                    std::to_string(kJobSchemaVersion) +
                                    " (written by a newer ParaPM?)");
  for (; version < kJobSchemaVersion; ++version) {
    const std::string what = "migrating the schema to version " + std::to_string(version + 1);
    sqlite::Transaction transaction(db, what);
    db.exec(kMigrations[version], what);
    transaction.commit();
    spdlog::info("job store: {} now has schema version {}", db.file().string(), version + 1);
  }
}

}  // namespace parapm::service
