// The service against hostile and careless clients, with real processes on loopback: streams
// that are opened and never used, a gzip bomb, oversized chunks, and stored bytes changed
// behind the coordinator's back. After each the service still builds a good mesh.
#include <sys/wait.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>

#include "io/byte_output.h"
#include "rpc_security.h"
#include "service_fixture.h"

namespace parapm::service_test {
namespace {

using Clock = std::chrono::steady_clock;

class ServiceHostile : public ServiceTest {
 protected:
  // Peak resident memory of the coordinator so far, bytes (VmHWM).
  uint64_t coordinator_peak_bytes() {
    std::ifstream status("/proc/" + std::to_string(service().coordinator().pid()) + "/status");
    std::string line;
    while (std::getline(status, line))
      if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
    ADD_FAILURE() << "no VmHWM for the coordinator";
    return 0;
  }

  fs::path blob_path(const std::string& sha) {
    return dir() / "data" / "blobs" / sha.substr(0, 2) / sha;
  }
};

// An upload stream opened and left silent, as a careless client does.
struct SilentUpload {
  grpc::ClientContext context;
  parapm::v1::UploadReply reply;
  std::unique_ptr<grpc::ClientWriter<parapm::v1::UploadChunk>> writer;

  SilentUpload(parapm::v1::MeshService::Stub& stub, const std::string& token) {
    context.set_deadline(std::chrono::system_clock::now() + seconds(30));
    rpc::attach_token(context, token);
    writer = stub.Upload(&context, &reply);
  }
};

// Streams held open without a word used to take every server thread (heartbeats were refused
// and the worker declared dead). Now a client's streams beyond its bound are refused at once,
// silent ones are closed after the idle limit, and the worker keeps beating throughout.
TEST_F(ServiceHostile, SilentStreamsAreBoundedAndClosedWhileWorkersKeepBeating) {
  service().set_token("hostile-test-token");
  start(1, {"--max-streams-per-client", "4", "--stream-idle-s", "2", "--heartbeat-ms", "200"});
  std::vector<std::unique_ptr<SilentUpload>> silent;
  for (int i = 0; i < 4; ++i)
    silent.push_back(std::make_unique<SilentUpload>(service().stub(), service().token()));
  // The four are admitted once the server has seen them: poll with a fifth until it is refused.
  grpc::Status refused;
  const auto deadline = Clock::now() + seconds(5);
  while (Clock::now() < deadline) {
    parapm::v1::UploadReply reply;
    refused = service().try_upload("fifth.obj", "v 0 0 0\n", &reply);
    if (refused.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED) break;
    std::this_thread::sleep_for(milliseconds(50));
  }
  ASSERT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status_text(refused);
  EXPECT_NE(refused.error_message().find("this client"), std::string::npos)
      << refused.error_message();
  // Unary calls still answer while the client's streams are full.
  parapm::v1::Job job;
  EXPECT_EQ(service().try_get_job("job-unknown", &job).error_code(), grpc::StatusCode::NOT_FOUND);

  // The idle limit closes all four (2 s, and the watchdog's look every 0.5 s).
  const auto opened = Clock::now();
  for (auto& upload : silent) {
    const grpc::Status status = upload->writer->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::CANCELLED) << status_text(status);
  }
  EXPECT_LT(Clock::now() - opened, seconds(10));
  silent.clear();
  expect_serves(1);
  EXPECT_EQ(service().coordinator().log().find("missed"), std::string::npos)
      << "the worker was declared dead";
  EXPECT_NE(service().coordinator().log().find("moved nothing for 2 s"), std::string::npos);
}

// The idle limit waits on the client, not on the server: an upload whose parsing takes longer
// than the idle limit (a 1.3M-face grid, 0.1 s) is not cut off, and neither is its download.
TEST_F(ServiceHostile, TheIdleLimitDoesNotCountTheServersOwnWork) {
  start(1, {"--stream-idle-s", "0.1"});
  std::string obj;
  constexpr int kSide = 800;
  for (int y = 0; y <= kSide; ++y)
    for (int x = 0; x <= kSide; ++x)
      obj += "v " + std::to_string(x) + " " + std::to_string(y) + " " +
             std::to_string((x * y) % 7) + "\n";
  auto id = [](int x, int y) { return std::to_string(y * (kSide + 1) + x + 1); };
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x)
      obj += "f " + id(x, y) + " " + id(x + 1, y) + " " + id(x + 1, y + 1) + "\nf " + id(x, y) +
             " " + id(x + 1, y + 1) + " " + id(x, y + 1) + "\n";
  parapm::v1::UploadReply reply;
  const grpc::Status status = service().try_upload("grid.obj", obj, &reply);
  ASSERT_TRUE(status.ok()) << status_text(status);
  EXPECT_EQ(reply.faces(), 2u * kSide * kSide);
  EXPECT_EQ(service().coordinator().log().find("moved nothing"), std::string::npos);
}

// Unary calls are bounded too (each holds a thread while it runs): eight threads asking at once
// with a bound of one call per client get answers or RESOURCE_EXHAUSTED, nothing else, and the
// worker keeps beating.
TEST_F(ServiceHostile, UnaryCallsAreBoundedPerClient) {
  start(1, {"--max-calls-per-client", "1", "--heartbeat-ms", "200"});
  std::atomic<int> answered = 0, refused = 0, other = 0;
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&] {
      for (int i = 0; i < 200; ++i) {
        parapm::v1::Job job;
        const grpc::Status status = service().try_get_job("job-unknown", &job);
        if (status.error_code() == grpc::StatusCode::NOT_FOUND)
          ++answered;
        else if (status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED &&
                 status.error_message().find("calls open, the limit per client") !=
                     std::string::npos)
          ++refused;
        else
          ++other;
      }
    });
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(other, 0);
  EXPECT_GT(answered, 0);
  EXPECT_GT(refused, 0);
  std::printf("unary flood: %d answered, %d refused\n", answered.load(), refused.load());
  expect_serves(3);
  EXPECT_EQ(service().coordinator().log().find("missed"), std::string::npos);
}

// 256 MiB of zeros named .ply.gz used to be inflated whole (with buffer doubling) before its
// first line was read. Now inflation stops after the first 64 KiB, which are no PLY header; a
// bomb that does look like a mesh stops at --max-mesh-mb; a chunk larger than the API's 4 MiB
// is refused.
TEST_F(ServiceHostile, GzipBombCostsLittleAndStopsAtTheInflatedLimit) {
  start(1, {"--max-mesh-mb", "8"});
  const uint64_t idle_peak = coordinator_peak_bytes();
  const std::string zeros = io::gzip_compress(std::string(size_t(256) << 20, '\0'));
  parapm::v1::UploadReply reply;
  grpc::Status status = service().try_upload("bomb.ply.gz", zeros, &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status_text(status);
  EXPECT_NE(status.error_message().find("not a PLY file"), std::string::npos)
      << status.error_message();
  EXPECT_LT(coordinator_peak_bytes(), idle_peak + (64u << 20));

  const std::string ply_bomb = io::gzip_compress("ply\n" + std::string(size_t(64) << 20, ' '));
  status = service().try_upload("bomb2.ply.gz", ply_bomb, &reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status_text(status);
  EXPECT_NE(status.error_message().find("limit of 8388608 bytes"), std::string::npos)
      << status.error_message();

  const std::string big = read_binary(mesh("pymeshlab-colored-airplane-11k.ply"));
  status = service().try_upload("airplane.ply", big + std::string(6 << 20, '\n'), &reply,
                                std::nullopt, size_t(5) << 20);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status_text(status);
  expect_serves(2);
}

// A byte flipped in a stored PM used to be served with OK; one flipped in a stored mesh made a
// job end DONE with a PM that no longer rebuilt the upload. Now each read is checked against
// the blob's hash: DATA_LOSS naming no server path, the job marked failed, and --verify lists
// both blobs.
TEST_F(ServiceHostile, ChangedStoredBytesAreDataLossNeverServed) {
  start(1);
  const fs::path file = mesh("cad-featuretype-3k.stl");
  const auto upload = service().upload_file(file);
  const auto done = service().wait_for_job(
      service().submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.2)).job_id(),
      seconds(30));
  ASSERT_EQ(done.state(), parapm::v1::DONE) << done.failure_reason();

  auto flip_a_byte = [&](const std::string& sha) {
    std::string bytes = read_binary(blob_path(sha));
    bytes[bytes.size() / 2] ^= 0x01;
    write_binary(blob_path(sha), bytes);
  };
  flip_a_byte(done.pm_sha256());
  // The coordinator serves a PM it wrote from memory, as written; a fresh one reads its blob.
  service().kill_coordinator();
  service().restart_coordinator();
  std::string pm;
  const grpc::Status status = service().try_download(done.job_id(), &pm);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DATA_LOSS) << status_text(status);
  EXPECT_NE(status.error_message().find(done.pm_sha256()), std::string::npos);
  EXPECT_EQ(status.error_message().find(dir().string()), std::string::npos)
      << status.error_message();
  const parapm::v1::Job marked = service().get_job(done.job_id());
  EXPECT_EQ(marked.state(), parapm::v1::FAILED);
  EXPECT_NE(marked.failure_reason().find("corrupt"), std::string::npos) << marked.failure_reason();

  flip_a_byte(upload.content_sha256());
  const auto rerun = service().wait_for_job(
      service().submit(upload.mesh_id(), options(2, parapm::v1::METRIC_QUADRIC, 0.2)).job_id(),
      seconds(30));
  EXPECT_EQ(rerun.state(), parapm::v1::FAILED);
  EXPECT_NE(rerun.failure_reason().find("corrupt"), std::string::npos) << rerun.failure_reason();
  EXPECT_EQ(rerun.failure_reason().find(dir().string()), std::string::npos);

  ChildProcess verify("verify",
                      {std::string(PARAPM_BINARY_DIR) + "/parapm-coordinator", "--verify", "--data",
                       (dir() / "data").string()},
                      dir() / "verify.log");
  const std::optional<int> exit = verify.wait(seconds(30));
  ASSERT_TRUE(exit.has_value());
  EXPECT_TRUE(WIFEXITED(*exit) && WEXITSTATUS(*exit) == 1) << verify.log();
  EXPECT_NE(verify.log().find("corrupt: " + done.pm_sha256()), std::string::npos) << verify.log();
  EXPECT_NE(verify.log().find("corrupt: " + upload.content_sha256()), std::string::npos);
}

// `--parallel 256 --min-subset-faces 1` on a few thousand faces used to run 64 rounds of almost
// nothing (16k worker calls). Options that can only waste work are refused, naming what the
// mesh can use; a job that leaves p to the coordinator gets as many as its mesh can use.
TEST_F(ServiceHostile, WastefulOptionsAreRefusedAndSmallMeshesGetAUsefulP) {
  start(1);
  const auto upload = service().upload_file(mesh("cad-featuretype-3k.stl"));
  const uint64_t most = upload.faces() / 50;
  parapm::v1::Job job;
  parapm::v1::JobOptions greedy = options(256, parapm::v1::METRIC_QUADRIC, 0.1);
  greedy.set_min_subset_faces(0);
  grpc::Status status = service().try_submit(upload.mesh_id(), greedy, &job);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status_text(status);
  EXPECT_NE(status.error_message().find("at most " + std::to_string(most)), std::string::npos)
      << status.error_message();
  parapm::v1::JobOptions tiny_subsets = options(2, parapm::v1::METRIC_QUADRIC, 0.1);
  tiny_subsets.set_min_subset_faces(1);
  status = service().try_submit(upload.mesh_id(), tiny_subsets, &job);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status_text(status);
  EXPECT_NE(status.error_message().find("min_subset_faces must be 0 or at least 50"),
            std::string::npos)
      << status.error_message();

  // A single triangle with the coordinator's default p (4): p = 1, and a lossless PM.
  parapm::v1::UploadReply triangle;
  ASSERT_TRUE(
      service().try_upload("triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", &triangle).ok());
  const auto done = service().wait_for_job(
      service().submit(triangle.mesh_id(), options(0, parapm::v1::METRIC_QUADRIC, 0)).job_id(),
      seconds(30));
  ASSERT_EQ(done.state(), parapm::v1::DONE) << done.failure_reason();
  EXPECT_EQ(done.options().parallelism(), 1u);
}

}  // namespace
}  // namespace parapm::service_test
