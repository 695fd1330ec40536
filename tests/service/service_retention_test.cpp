// Deleting jobs and meshes, and the retention that does it by age: rows go, and the stored
// files no row names any more go with them; live jobs are never deleted.
#include <chrono>
#include <regex>
#include <thread>

#include "rpc_security.h"
#include "service_fixture.h"

namespace parapm::service_test {
namespace {

class ServiceRetention : public ServiceTest {
 protected:
  fs::path blobs_dir() { return dir() / "data" / "blobs"; }

  // The stored blobs' names (the temp folder left out).
  std::set<std::string> blob_names() {
    std::set<std::string> names;
    for (const auto& shard : fs::directory_iterator(blobs_dir()))
      if (shard.is_directory() && shard.path().filename() != "tmp")
        for (const auto& entry : fs::directory_iterator(shard.path()))
          names.insert(entry.path().filename().string());
    return names;
  }

  // Garbage collection spares blobs younger than a minute (a blob is written before the row
  // that names it): make every blob look older.
  void age_blobs() {
    for (const auto& shard : fs::directory_iterator(blobs_dir()))
      if (shard.is_directory() && shard.path().filename() != "tmp")
        for (const auto& entry : fs::directory_iterator(shard.path()))
          fs::last_write_time(entry.path(),
                              fs::file_time_type::clock::now() - std::chrono::minutes(2));
  }

  grpc::Status delete_job(const std::string& job_id, parapm::v1::DeleteReply* reply) {
    grpc::ClientContext context;
    rpc::attach_token(context, service().token());
    parapm::v1::JobRef ref;
    ref.set_job_id(job_id);
    return service().stub().DeleteJob(&context, ref, reply);
  }

  grpc::Status delete_mesh(const std::string& mesh_id, parapm::v1::DeleteReply* reply) {
    grpc::ClientContext context;
    rpc::attach_token(context, service().token());
    parapm::v1::MeshRef ref;
    ref.set_mesh_id(mesh_id);
    return service().stub().DeleteMesh(&context, ref, reply);
  }

  parapm::v1::Job build(const std::string& mesh_id, double ratio) {
    const auto job = service().wait_for_job(
        service().submit(mesh_id, options(2, parapm::v1::METRIC_QUADRIC, ratio)).job_id(),
        seconds(30));
    EXPECT_EQ(job.state(), parapm::v1::DONE) << job.failure_reason();
    return job;
  }
};

TEST_F(ServiceRetention, DeletedJobsAndMeshesTakeTheirStoredFilesAlong) {
  start(1);
  const auto upload = service().upload_file(mesh("cad-featuretype-3k.stl"));
  const auto first = build(upload.mesh_id(), 0.2);
  const auto second = build(upload.mesh_id(), 0.3);
  ASSERT_NE(first.pm_sha256(), second.pm_sha256());
  EXPECT_EQ(blob_names(), (std::set<std::string>{upload.content_sha256(), first.pm_sha256(),
                                                 second.pm_sha256()}));
  age_blobs();

  parapm::v1::DeleteReply reply;
  ASSERT_TRUE(delete_job(first.job_id(), &reply).ok());
  EXPECT_EQ(reply.jobs_deleted(), 1u);
  EXPECT_EQ(reply.blobs_removed(), 1u);
  EXPECT_GT(reply.bytes_freed(), 0u);
  EXPECT_EQ(blob_names(), (std::set<std::string>{upload.content_sha256(), second.pm_sha256()}));
  parapm::v1::Job gone;
  EXPECT_EQ(service().try_get_job(first.job_id(), &gone).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(delete_job(first.job_id(), &reply).error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_FALSE(service().download(second.job_id()).empty());

  // With the command-line client: the mesh and its last job.
  const CliResult deleted = run_parapm(
      {"delete", "--mesh", upload.mesh_id(), "--json", "--server", service().address()}, dir());
  ASSERT_EQ(deleted.exit_code, 0) << deleted.output;
  EXPECT_NE(deleted.output.find("\"meshes_deleted\":\"1\""), std::string::npos) << deleted.output;
  EXPECT_TRUE(blob_names().empty());
  EXPECT_EQ(service().try_get_job(second.job_id(), &gone).error_code(),
            grpc::StatusCode::NOT_FOUND);
  // The same bytes again are a new mesh, and build.
  const auto again = service().upload_file(mesh("cad-featuretype-3k.stl"));
  EXPECT_NE(again.mesh_id(), upload.mesh_id());
  build(again.mesh_id(), 0.2);
}

// Without a worker a job waits for one (running, its subsets unsent): neither it nor its mesh
// can be deleted until it has been cancelled.
TEST_F(ServiceRetention, LiveJobsAreNeverDeleted) {
  service().start_coordinator();
  const auto upload = service().upload_file(mesh("cad-featuretype-3k.stl"));
  // Rounds (subsets of 1000 faces) so that the job waits for a worker.
  parapm::v1::JobOptions rounds = options(2, parapm::v1::METRIC_QUADRIC, 0.2);
  rounds.set_min_subset_faces(1000);
  const auto queued = service().submit(upload.mesh_id(), rounds);
  parapm::v1::DeleteReply reply;
  grpc::Status status = delete_job(queued.job_id(), &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << status_text(status);
  EXPECT_NE(status.error_message().find("cancel it first"), std::string::npos);
  status = delete_mesh(upload.mesh_id(), &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION) << status_text(status);
  const parapm::v1::JobState state = service().get_job(queued.job_id()).state();
  EXPECT_TRUE(state == parapm::v1::QUEUED || state == parapm::v1::RUNNING) << state;
  service().cancel_job(queued.job_id());
  EXPECT_EQ(service().wait_for_job(queued.job_id(), seconds(10)).state(), parapm::v1::CANCELLED);
  ASSERT_TRUE(delete_mesh(upload.mesh_id(), &reply).ok());
  EXPECT_EQ(reply.jobs_deleted(), 1u);
  EXPECT_EQ(reply.meshes_deleted(), 1u);
}

// --retain-days: jobs that ended longer ago, and meshes as old without a job, go by themselves.
TEST_F(ServiceRetention, RetentionDeletesWhatEndedLongAgo) {
  // 0.00003 days: 2.6 s.
  start(1, {"--retain-days", "0.00003", "--retention-check-s", "0.2"});
  const auto upload = service().upload_file(mesh("cad-featuretype-3k.stl"));
  const auto job = build(upload.mesh_id(), 0.2);
  parapm::v1::Job found;
  EXPECT_TRUE(service().try_get_job(job.job_id(), &found).ok());  // not yet
  grpc::Status status;
  for (int i = 0; i < 200; ++i) {
    status = service().try_get_job(job.job_id(), &found);
    if (status.error_code() == grpc::StatusCode::NOT_FOUND) break;
    std::this_thread::sleep_for(milliseconds(50));
  }
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND) << status_text(status);
  // The mesh goes in the same pass, after its job, or in the next one: waited for in the log
  // (a submission meanwhile would be a new job that keeps it), then it is gone for a client.
  const std::regex mesh_deleted("retention: [0-9]+ jobs, [1-9][0-9]* meshes");
  bool gone = false;
  for (int i = 0; i < 200 && !gone; ++i) {
    gone = std::regex_search(service().coordinator().log(), mesh_deleted);
    if (!gone) std::this_thread::sleep_for(milliseconds(50));
  }
  ASSERT_TRUE(gone) << service().coordinator().log();
  status =
      service().try_submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.2), &found);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND) << status_text(status);
  EXPECT_NE(service().coordinator().log().find("retention: 1 jobs"), std::string::npos)
      << service().coordinator().log();
}

// --retain-gb: while the blobs take more, the oldest ended jobs go (then meshes without a job
// uploaded over an hour ago), and their files once they are no younger than a minute.
TEST_F(ServiceRetention, RetentionKeepsTheStoreUnderItsSize) {
  start(1, {"--retain-gb", "0.000001", "--retention-check-s", "0.2"});  // about 1 KiB
  const auto upload = service().upload_file(mesh("cad-featuretype-3k.stl"));
  const auto job = service().submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.2));
  // The job ends, and goes at the next check.
  parapm::v1::Job found;
  grpc::Status status;
  for (int i = 0; i < 200; ++i) {
    status = service().try_get_job(job.job_id(), &found);
    if (status.error_code() == grpc::StatusCode::NOT_FOUND) break;
    std::this_thread::sleep_for(milliseconds(50));
  }
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND) << status_text(status);
  age_blobs();
  const std::set<std::string> mesh_only = {upload.content_sha256()};
  for (int i = 0; i < 200 && blob_names() != mesh_only; ++i)
    std::this_thread::sleep_for(milliseconds(50));
  EXPECT_EQ(blob_names(), mesh_only);  // the fresh mesh is spared
  EXPECT_TRUE(service()
                  .try_submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.2), &found)
                  .ok());
}

}  // namespace
}  // namespace parapm::service_test
