// The job database's schema and its migrations. PRAGMA user_version holds the schema version:
// 0 is a new, empty file; each migration moves the file up one version in its own
// transaction, so a crash mid-migration leaves the previous version intact.
#pragma once

#include "storage/sqlite.h"

namespace parapm::service {

inline constexpr int kJobSchemaVersion = 1;

// Brings the file up to kJobSchemaVersion. Throws kIo for a file written by a newer build
// (its schema is unknown here) or one that is not a SQLite database.
void migrate_job_schema(sqlite::Database& db);

}  // namespace parapm::service
