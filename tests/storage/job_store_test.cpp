// The job database on a real SQLite file: meshes and jobs round-trip every field, lookups,
// ordering of the job list and of the restart queue, and the errors for missing or duplicate
// rows.
#include <gtest/gtest.h>

#include <string>

#include "storage/job_store.h"
#include "storage_test_util.h"

namespace parapm::service {
namespace {

using testing::expect_error;
using testing::TempDir;

MeshRecord a_mesh(const std::string& id, const std::string& sha, int64_t created_unix_ms = 1000) {
  MeshRecord mesh;
  mesh.mesh_id = id;
  mesh.sha256 = sha;
  mesh.file_name = "bunny.ply";
  mesh.bytes = 123456;
  mesh.vertices = 5000;
  mesh.faces = 9998;
  mesh.created_unix_ms = created_unix_ms;
  return mesh;
}

JobRecord a_job(const std::string& id, const std::string& mesh_id, int64_t created_unix_ms,
                JobStatus status = JobStatus::kQueued) {
  JobRecord job;
  job.job_id = id;
  job.mesh_id = mesh_id;
  job.options = std::string("\x08\x01\x00\xff options", 12);  // binary, with a NUL
  job.status = status;
  job.created_unix_ms = created_unix_ms;
  job.updated_unix_ms = created_unix_ms;
  return job;
}

void expect_same(const JobRecord& a, const JobRecord& b) {
  EXPECT_EQ(a.job_id, b.job_id);
  EXPECT_EQ(a.mesh_id, b.mesh_id);
  EXPECT_EQ(a.options, b.options);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.failure_reason, b.failure_reason);
  EXPECT_EQ(a.pm_sha256, b.pm_sha256);
  EXPECT_EQ(a.input_faces, b.input_faces);
  EXPECT_EQ(a.base_faces, b.base_faces);
  EXPECT_EQ(a.vsplits, b.vsplits);
  EXPECT_EQ(a.seconds, b.seconds);
  EXPECT_EQ(a.attempts, b.attempts);
  EXPECT_EQ(a.created_unix_ms, b.created_unix_ms);
  EXPECT_EQ(a.updated_unix_ms, b.updated_unix_ms);
}

std::vector<std::string> ids_of(const std::vector<JobRecord>& jobs) {
  std::vector<std::string> ids;
  for (const JobRecord& job : jobs) ids.push_back(job.job_id);
  return ids;
}

class JobStoreTest : public ::testing::Test {
 protected:
  TempDir dir_;
  JobStore store_{dir_.path() / "parapm.db"};
};

TEST(JobStatusText, RoundTripsAndRefusesUnknown) {
  for (JobStatus status : {JobStatus::kQueued, JobStatus::kRunning, JobStatus::kDone,
                           JobStatus::kFailed, JobStatus::kCancelled})
    EXPECT_EQ(parse_job_status(to_string(status)), status);
  EXPECT_EQ(parse_job_status("QUEUED"), std::nullopt);
  EXPECT_EQ(parse_job_status(""), std::nullopt);
}

TEST(NewId, HasThePrefixAnd16HexCharacters) {
  const std::string id = new_id("job-");
  ASSERT_EQ(id.size(), 20u);
  EXPECT_EQ(id.substr(0, 4), "job-");
  EXPECT_EQ(id.find_first_not_of("0123456789abcdef", 4), std::string::npos);
  EXPECT_NE(new_id("job-"), new_id("job-"));
}

TEST_F(JobStoreTest, MeshRoundTripsAndIsFoundByHash) {
  const MeshRecord mesh = a_mesh("mesh-1", std::string(64, 'a'));
  store_.add_mesh(mesh);
  const auto found = store_.find_mesh("mesh-1");
  ASSERT_TRUE(found);
  EXPECT_EQ(found->sha256, mesh.sha256);
  EXPECT_EQ(found->file_name, "bunny.ply");
  EXPECT_EQ(found->bytes, 123456u);
  EXPECT_EQ(found->vertices, 5000u);
  EXPECT_EQ(found->faces, 9998u);
  EXPECT_EQ(found->created_unix_ms, 1000);
  EXPECT_FALSE(store_.find_mesh("mesh-2"));
  EXPECT_FALSE(store_.find_mesh_by_sha256(std::string(64, 'b')));
}

TEST_F(JobStoreTest, FindByHashGivesTheOldestUpload) {
  const std::string sha(64, 'c');
  store_.add_mesh(a_mesh("mesh-late", sha, 2000));
  store_.add_mesh(a_mesh("mesh-early", sha, 1000));
  EXPECT_EQ(store_.find_mesh_by_sha256(sha)->mesh_id, "mesh-early");
}

TEST_F(JobStoreTest, DuplicateMeshIdIsInvalidInput) {
  store_.add_mesh(a_mesh("mesh-1", std::string(64, 'a')));
  expect_error([&] { store_.add_mesh(a_mesh("mesh-1", std::string(64, 'b'))); },
               ErrorCode::kInvalidInput, {"adding mesh mesh-1", "UNIQUE constraint failed"});
}

TEST_F(JobStoreTest, JobRoundTripsEveryField) {
  store_.add_mesh(a_mesh("mesh-1", std::string(64, 'a')));
  JobRecord job = a_job("job-1", "mesh-1", 1000);
  store_.add_job(job);
  expect_same(*store_.find_job("job-1"), job);

  job.status = JobStatus::kDone;
  job.failure_reason = "";
  job.pm_sha256 = std::string(64, 'd');
  job.input_faces = 69451;
  job.base_faces = 200;
  job.vsplits = 34600;
  job.seconds = 0.8125;
  job.attempts = 2;
  job.updated_unix_ms = 5000;
  job.options = "";
  store_.update_job(job);
  expect_same(*store_.find_job("job-1"), job);

  job.status = JobStatus::kFailed;
  job.failure_reason = "mesh has no faces";
  store_.update_job(job);
  expect_same(*store_.find_job("job-1"), job);
  EXPECT_FALSE(store_.find_job("job-2"));
}

TEST_F(JobStoreTest, JobForAMissingMeshIsNotFound) {
  expect_error([&] { store_.add_job(a_job("job-1", "mesh-nope", 1000)); }, ErrorCode::kNotFound,
               {"adding job job-1 for mesh mesh-nope", "FOREIGN KEY"});
}

TEST_F(JobStoreTest, UpdatingAMissingJobThrows) {
  store_.add_mesh(a_mesh("mesh-1", std::string(64, 'a')));
  expect_error([&] { store_.update_job(a_job("job-ghost", "mesh-1", 1000)); }, ErrorCode::kNotFound,
               {"job-ghost", "no such job"});
  EXPECT_FALSE(store_.find_job("job-ghost"));
}

TEST_F(JobStoreTest, BadValuesAreInvalidInput) {
  store_.add_mesh(a_mesh("mesh-1", std::string(64, 'a')));
  expect_error([&] { store_.add_job(a_job("", "mesh-1", 1000)); }, ErrorCode::kInvalidInput,
               {"needs a job_id"});
  JobRecord huge = a_job("job-1", "mesh-1", 1000);
  huge.vsplits = UINT64_MAX;
  expect_error([&] { store_.add_job(huge); }, ErrorCode::kInvalidInput,
               {"does not fit a 64-bit signed integer"});
  EXPECT_FALSE(store_.find_job("job-1"));
}

TEST_F(JobStoreTest, ListIsNewestFirstWithTiesById) {
  store_.add_mesh(a_mesh("mesh-1", std::string(64, 'a')));
  store_.add_job(a_job("job-b", "mesh-1", 2000));
  store_.add_job(a_job("job-a", "mesh-1", 2000));
  store_.add_job(a_job("job-old", "mesh-1", 1000));
  store_.add_job(a_job("job-new", "mesh-1", 3000));
  EXPECT_EQ(ids_of(store_.list_jobs(10)),
            (std::vector<std::string>{"job-new", "job-a", "job-b", "job-old"}));
  EXPECT_EQ(ids_of(store_.list_jobs(2)), (std::vector<std::string>{"job-new", "job-a"}));
  EXPECT_TRUE(store_.list_jobs(0).empty());
}

TEST_F(JobStoreTest, RestartQueueIsOldestFirstAndOnlyTheAskedStatuses) {
  store_.add_mesh(a_mesh("mesh-1", std::string(64, 'a')));
  store_.add_job(a_job("job-3", "mesh-1", 3000, JobStatus::kQueued));
  store_.add_job(a_job("job-1", "mesh-1", 1000, JobStatus::kRunning));
  store_.add_job(a_job("job-2", "mesh-1", 2000, JobStatus::kDone));
  store_.add_job(a_job("job-0", "mesh-1", 500, JobStatus::kFailed));
  store_.add_job(a_job("job-4", "mesh-1", 3000, JobStatus::kQueued));
  store_.add_job(a_job("job-5", "mesh-1", 100, JobStatus::kCancelled));
  EXPECT_EQ(ids_of(store_.jobs_with_status({JobStatus::kQueued, JobStatus::kRunning})),
            (std::vector<std::string>{"job-1", "job-3", "job-4"}));
  EXPECT_EQ(ids_of(store_.jobs_with_status({JobStatus::kDone})),
            (std::vector<std::string>{"job-2"}));
  EXPECT_EQ(ids_of(store_.jobs_with_status({JobStatus::kQueued, JobStatus::kRunning,
                                            JobStatus::kDone, JobStatus::kFailed,
                                            JobStatus::kCancelled, JobStatus::kQueued})),
            (std::vector<std::string>{"job-5", "job-0", "job-1", "job-2", "job-3", "job-4"}));
  EXPECT_TRUE(store_.jobs_with_status({}).empty());
}

TEST_F(JobStoreTest, JobCountsAreByStateAndFollowUpdates) {
  EXPECT_TRUE(store_.job_counts().empty());
  store_.add_mesh(a_mesh("mesh-1", std::string(64, 'a')));
  store_.add_job(a_job("job-1", "mesh-1", 1000, JobStatus::kQueued));
  store_.add_job(a_job("job-2", "mesh-1", 2000, JobStatus::kQueued));
  store_.add_job(a_job("job-3", "mesh-1", 3000, JobStatus::kDone));
  JobRecord running = a_job("job-2", "mesh-1", 2000, JobStatus::kRunning);
  store_.update_job(running);
  EXPECT_EQ(store_.job_counts(),
            (std::map<JobStatus, uint64_t>{
                {JobStatus::kQueued, 1}, {JobStatus::kRunning, 1}, {JobStatus::kDone, 1}}));
  store_.delete_job("job-3");
  EXPECT_EQ(store_.job_counts().count(JobStatus::kDone), 0u);
}

}  // namespace
}  // namespace parapm::service
