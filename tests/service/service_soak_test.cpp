// A bounded soak: many clients at once upload, submit, watch, download, stream and cancel while a
// worker is killed and another started, against a coordinator with small stream bounds. It
// ends with every job done or cancelled, every done PM lossless, every client thread back
// (no stuck stream), and the coordinator's memory back near where it started. Its figures
// are printed for docs/BENCHMARKS.md ("Soak").
#include <atomic>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <thread>

#include "rpc_security.h"
#include "service_fixture.h"

namespace parapm::service_test {
namespace {

uint64_t resident_bytes(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  return 0;
}

class ServiceSoak : public ServiceTest {};

TEST_F(ServiceSoak, ManyClientsAndAWorkerKilledLoseNothing) {
  start(2, {"--max-streams-per-client", "8", "--stream-idle-s", "5"});
  const uint64_t idle_bytes = resident_bytes(service().coordinator().pid());
  const std::vector<std::string> files = {"cad-featuretype-3k.stl", "stratocaster-9k.ply",
                                          "pymeshlab-colored-airplane-11k.ply"};
  constexpr int kClients = 6, kJobsPerClient = 4;
  std::atomic<int> requests = 0, refused = 0, done = 0, cancelled = 0;
  std::mutex failures_mutex;
  std::vector<std::string> failures;
  auto fail = [&](const std::string& what) {
    std::lock_guard lock(failures_mutex);
    failures.push_back(what);
  };
  auto client = [&](int c) {
    for (int j = 0; j < kJobsPerClient; ++j) {
      const fs::path file = mesh(files[size_t(c + j) % files.size()]);
      parapm::v1::UploadReply upload;
      grpc::Status status;
      // A full coordinator answers RESOURCE_EXHAUSTED: retry, as its message says.
      for (int attempt = 0; attempt < 50; ++attempt) {
        ++requests;
        status = service().try_upload(file.filename().string(), read_binary(file), &upload);
        if (status.error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED) break;
        ++refused;
        std::this_thread::sleep_for(milliseconds(100));
      }
      if (!status.ok()) return fail("upload: " + status_text(status));
      parapm::v1::JobOptions o = options(2, parapm::v1::METRIC_QUADRIC, 0.1, uint64_t(c * 10 + j));
      o.set_min_subset_faces(1000);
      parapm::v1::Job job;
      ++requests;
      status = service().try_submit(upload.mesh_id(), o, &job);
      if (!status.ok()) return fail("submit: " + status_text(status));
      if (j == 1) {  // every client cancels one job, whatever state it is in
        ++requests;
        service().cancel_job(job.job_id());
      }
      ++requests;
      const parapm::v1::Job ended = service().wait_for_job(job.job_id(), seconds(120));
      if (ended.state() == parapm::v1::CANCELLED) {
        ++cancelled;
        continue;
      }
      if (ended.state() != parapm::v1::DONE)
        return fail(job.job_id() + " ended " + std::to_string(ended.state()) + ": " +
                    ended.failure_reason());
      std::string pm;
      for (int attempt = 0; attempt < 50; ++attempt) {
        ++requests;
        status = service().try_download(job.job_id(), &pm);
        if (status.error_code() != grpc::StatusCode::RESOURCE_EXHAUSTED) break;
        ++refused;
        std::this_thread::sleep_for(milliseconds(100));
      }
      if (!status.ok()) return fail("download: " + status_text(status));
      if (const std::string bad = lossless_failure(pm, file, dir()); !bad.empty())
        return fail(job.job_id() + " not lossless: " + bad);
      if (j == 2) {  // a viewer's stream too: every vsplit arrives, the same bytes
        grpc::ClientContext context;
        context.set_deadline(std::chrono::system_clock::now() + seconds(60));
        rpc::attach_token(context, service().token());
        parapm::v1::StreamRequest request;
        request.set_job_id(job.job_id());
        request.set_batch_vsplits(256);
        ++requests;
        auto reader = service().stub().StreamPM(&context, request);
        parapm::v1::PmStreamMessage message;
        std::string streamed;
        uint64_t vsplits = 0;
        while (reader->Read(&message)) {
          streamed += message.header_and_base() + message.vsplit_batch();
          vsplits += message.count();
        }
        status = reader->Finish();
        if (!status.ok()) return fail("stream: " + status_text(status));
        if (vsplits != ended.vsplits() || pm.compare(0, streamed.size(), streamed) != 0)
          return fail(job.job_id() + ": the stream is not the PM's bytes");
      }
      ++done;
    }
  };
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) clients.emplace_back(client, c);
  // The fault: the first worker killed as soon as it holds a subset, a new one started a
  // moment later.
  for (int i = 0; i < 400 && service().worker("w1")->log().find(": started, ") == std::string::npos;
       ++i)
    std::this_thread::sleep_for(milliseconds(10));
  service().worker("w1")->kill_now();
  std::this_thread::sleep_for(milliseconds(500));
  service().start_worker("w3");
  for (std::thread& t : clients) t.join();

  for (const std::string& f : failures) ADD_FAILURE() << f;
  EXPECT_EQ(done + cancelled, kClients * kJobsPerClient);
  EXPECT_GE(cancelled, 1);
  EXPECT_NE(service().coordinator().log().find("failed on worker"), std::string::npos)
      << "the kill interrupted no subset";
  std::this_thread::sleep_for(milliseconds(500));
  const uint64_t after_bytes = resident_bytes(service().coordinator().pid());
  EXPECT_LT(after_bytes, idle_bytes + (150u << 20))
      << "idle " << idle_bytes << " bytes, after " << after_bytes;
  std::printf(
      "soak: %d clients, %d jobs (%d done and lossless, %d cancelled), %d requests "
      "(%d refused as full and retried), 1 worker killed and 1 started, coordinator "
      "memory %.0f MB idle, %.0f MB after\n",
      kClients, kClients * kJobsPerClient, done.load(), cancelled.load(), requests.load(),
      refused.load(), double(idle_bytes) / 1e6, double(after_bytes) / 1e6);
}

}  // namespace
}  // namespace parapm::service_test
