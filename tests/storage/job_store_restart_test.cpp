// "A restart loses nothing": close the stores, open them again on the same folder, and every
// mesh, job, event and blob is still there, and new events carry on from the last seq. Also
// the files a restart may meet instead of a good database: garbage, a folder, a newer schema.
#include <gtest/gtest.h>

#include <sqlite3.h>
#include <string>

#include "storage/blob_store.h"
#include "storage/job_store.h"
#include "storage_test_util.h"

namespace parapm::service {
namespace {

using testing::expect_error;
using testing::TempDir;

TEST(JobStoreRestart, ReopenedStoresStillHaveEverything) {
  TempDir dir;
  const auto db_file = dir.path() / "parapm.db";
  std::string mesh_sha, pm_sha;
  {
    BlobStore blobs(dir.path());
    JobStore store(db_file);
    // Blobs first, then the rows that name them: the documented order.
    mesh_sha = blobs.put("solid mesh bytes");
    MeshRecord mesh;
    mesh.mesh_id = "mesh-1";
    mesh.sha256 = mesh_sha;
    mesh.file_name = "part.stl";
    mesh.faces = 12;
    store.add_mesh(mesh);
    JobRecord running;
    running.job_id = "job-running";
    running.mesh_id = "mesh-1";
    running.status = JobStatus::kRunning;
    running.attempts = 1;
    running.created_unix_ms = 100;
    store.add_job(running);
    pm_sha = blobs.put("progressive mesh bytes");
    JobRecord done = running;
    done.job_id = "job-done";
    done.status = JobStatus::kDone;
    done.pm_sha256 = pm_sha;
    done.created_unix_ms = 50;
    store.add_job(done);
    store.append_event("job-running", 1, "started");
    store.append_event("job-running", 2, "50%");
    store.append_event("job-done", 3, "done");
  }

  BlobStore blobs(dir.path());
  JobStore store(db_file);
  ASSERT_TRUE(store.find_mesh("mesh-1"));
  EXPECT_EQ(store.find_mesh("mesh-1")->file_name, "part.stl");
  EXPECT_EQ(store.find_mesh_by_sha256(mesh_sha)->mesh_id, "mesh-1");
  EXPECT_EQ(blobs.read(mesh_sha), "solid mesh bytes");
  const auto done = store.find_job("job-done");
  ASSERT_TRUE(done);
  EXPECT_EQ(done->status, JobStatus::kDone);
  EXPECT_EQ(blobs.read(done->pm_sha256), "progressive mesh bytes");
  const auto queue = store.jobs_with_status({JobStatus::kQueued, JobStatus::kRunning});
  ASSERT_EQ(queue.size(), 1u);
  EXPECT_EQ(queue[0].job_id, "job-running");
  EXPECT_EQ(queue[0].attempts, 1u);
  const auto events = store.events("job-running", 0);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].payload, "50%");
  EXPECT_EQ(store.append_event("job-running", 4, "restarted"), 3u) << "seq carries on";
  EXPECT_EQ(store.list_jobs(10).size(), 2u);
}

TEST(JobStoreRestart, GarbageFileIsAClearError) {
  TempDir dir;
  const auto db_file = dir.path() / "parapm.db";
  testing::write_file(db_file, std::string(8192, 'x') + "not a database at all");
  expect_error([&] { JobStore store(db_file); }, ErrorCode::kIo,
               {"job store", "file is not a database", db_file.string()});
}

TEST(JobStoreRestart, DamagedDatabaseIsAClearError) {
  TempDir dir;
  const auto db_file = dir.path() / "parapm.db";
  { JobStore store(db_file); }
  // Keep SQLite's header but overwrite the schema page: the file claims to be a database
  // and is not a readable one.
  std::string bytes = testing::read_file(db_file);
  ASSERT_GT(bytes.size(), 4096u);
  for (size_t i = 100; i < 4096; ++i) bytes[i] = static_cast<char>(0xA5 ^ i);
  testing::write_file(db_file, bytes);
  expect_error([&] { JobStore store(db_file); }, ErrorCode::kIo,
               {"job store", "malformed", db_file.string()});
}

TEST(JobStoreRestart, FolderInsteadOfAFileIsAClearError) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "parapm.db");
  expect_error([&] { JobStore store(dir.path() / "parapm.db"); }, ErrorCode::kIo,
               {"job store", "parapm.db"});
}

TEST(JobStoreRestart, NewerSchemaIsRefused) {
  TempDir dir;
  const auto db_file = dir.path() / "parapm.db";
  { JobStore store(db_file); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db_file.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "PRAGMA user_version = 99", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  expect_error([&] { JobStore store(db_file); }, ErrorCode::kIo,
               {"schema version 99", "newer ParaPM"});
}

}  // namespace
}  // namespace parapm::service
