// ParaPM's gRPC client (CMake: find_package(ParaPM) and link ParaPM::client): a connection to
// a coordinator and the calls that take more than one step. The API itself is the generated
// parapm::v1::MeshService (parapm.grpc.pb.h, docs/API.md); stub() reaches every RPC.
//
//   #include <parapm/client.h>
//
//   parapm::client::ServiceClient service({.server = "127.0.0.1:50051"});  // token: PARAPM_TOKEN
//   const auto mesh = service.upload("bunny.ply");
//   parapm::v1::JobOptions options;
//   options.set_target_ratio(0.02);
//   const auto job = service.submit(mesh.mesh_id(), options);
//   service.watch(job.job_id(), [](const parapm::v1::JobEvent& e) {
//     std::puts(parapm::client::describe_event(e).c_str());
//   });
//   service.download(job.job_id(), "bunny.pm");
//
// Every method throws parapm::Error (util/error.h) for a failed call: its code is the gRPC
// status's kind, its message "<what>: <CODE>: <the server's message>".
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>

#include "parapm.grpc.pb.h"
#include "util/error.h"

namespace parapm::client {

struct ConnectionOptions {
  std::string server;      // host:port; "" : PARAPM_SERVER, else kDefaultServer
  std::string token_file;  // "" : PARAPM_TOKEN, else no token (a loopback coordinator)
  bool tls = false;        // connect over TLS
  std::string tls_ca;      // PEM roots that sign the server's certificate ("" : the system's)
};

// The address `parapm up` serves on by default, and its viewer's.
constexpr const char* kDefaultServer = "127.0.0.1:50051";
constexpr const char* kDefaultViewer = "127.0.0.1:50052";

class ServiceClient {
 public:
  explicit ServiceClient(const ConnectionOptions& options);
  parapm::v1::MeshService::Stub& stub() { return *stub_; }
  const std::string& server() const { return server_; }
  const std::string& token() const { return token_; }
  // A context carrying the token; `timeout_s` 0: no deadline (streams that last a job).
  std::unique_ptr<grpc::ClientContext> context(double timeout_s = 60) const;

  // Uploads `path` in 1 MiB chunks (progress(sent, total) after each).
  parapm::v1::UploadReply upload(const std::filesystem::path& path,
                                 const std::function<void(uint64_t, uint64_t)>& progress = {});
  // Queues a job of an uploaded mesh.
  parapm::v1::Job submit(const std::string& mesh_id, const parapm::v1::JobOptions& options);
  // Follows the job's events to its end, calling on_event for each (a broken watch resumes
  // after the last event seen); returns the job as it ended.
  parapm::v1::Job watch(const std::string& job_id,
                        const std::function<void(const parapm::v1::JobEvent&)>& on_event);
  // Writes the job's .pm to `out` (a temp file renamed at the end: never a partial file).
  uint64_t download(const std::string& job_id, const std::filesystem::path& out);
  // Streams the job's PM (StreamPM): on_message for each message, base mesh first, then the
  // vsplits from request.from_vsplit() on, up to its limit. Returns the messages received.
  uint64_t stream(const parapm::v1::StreamRequest& request,
                  const std::function<void(const parapm::v1::PmStreamMessage&)>& on_message);
  // Writes a stream of chunks to `out` the same way as download; `what` names the call in errors.
  uint64_t receive_file(grpc::ClientReader<parapm::v1::Chunk>& reader,
                        const std::filesystem::path& out, const std::string& what);

 private:
  std::string server_;
  std::string token_;
  std::unique_ptr<parapm::v1::MeshService::Stub> stub_;
};

// Throws Error for a failed status: "<what>: <CODE>: <message>" (UNAVAILABLE names the server).
void check_status(const grpc::Status& status, const std::string& what, const std::string& server);

// One-line summaries for people.
const char* job_state_name(parapm::v1::JobState state);
std::string describe_event(const parapm::v1::JobEvent& event);

}  // namespace parapm::client
