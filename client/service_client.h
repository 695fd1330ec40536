// What the service commands (submit, jobs, watch, get, level, stream, cancel) share: the
// connection options (--server, --token-file, --tls, --tls-ca), the stub, and the calls that
// take more than one step (a chunked upload, watching a job to its end, a download).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include <grpcpp/grpcpp.h>
#include <CLI/CLI.hpp>

#include "parapm.grpc.pb.h"

namespace parapm::cli {

struct ConnectionArgs {
  std::string server;  // default: PARAPM_SERVER, else the local coordinator of `parapm up`
  std::string token_file;
  bool tls = false;
  std::string tls_ca;
};

// The address `parapm up` serves on by default, and its viewer's.
constexpr const char* kDefaultServer = "127.0.0.1:50051";
constexpr const char* kDefaultViewer = "127.0.0.1:50052";

void add_connection_options(CLI::App* command, ConnectionArgs& args);

class ServiceClient {
 public:
  explicit ServiceClient(const ConnectionArgs& args);
  parapm::v1::MeshService::Stub& stub() { return *stub_; }
  const std::string& server() const { return server_; }
  const std::string& token() const { return token_; }
  // A context carrying the token; `timeout_s` 0: no deadline (streams that last a job).
  std::unique_ptr<grpc::ClientContext> context(double timeout_s = 60) const;

  // Uploads `path` in 1 MiB chunks (progress on `progress`). Throws Error for a failed call.
  parapm::v1::UploadReply upload(const std::filesystem::path& path,
                                 const std::function<void(uint64_t, uint64_t)>& progress = {});
  // Follows the job's events to its end, calling on_event for each; returns the job.
  parapm::v1::Job watch(const std::string& job_id,
                        const std::function<void(const parapm::v1::JobEvent&)>& on_event);
  // Writes the job's .pm to `out` (a temp file renamed at the end: never a partial file).
  uint64_t download(const std::string& job_id, const std::filesystem::path& out);
  // Writes a stream of chunks to `out` the same way; `what` names the call in errors.
  uint64_t receive_file(grpc::ClientReader<parapm::v1::Chunk>& reader,
                        const std::filesystem::path& out, const std::string& what);

 private:
  std::string server_;
  std::string token_;
  std::unique_ptr<parapm::v1::MeshService::Stub> stub_;
};

// Throws Error for a failed status: "<what>: <CODE>: <message>" (UNAVAILABLE names the server).
void check_status(const grpc::Status& status, const std::string& what, const std::string& server);

// One-line summaries for people, JSON for scripts.
const char* job_state_name(parapm::v1::JobState state);
std::string describe_event(const parapm::v1::JobEvent& event);

}  // namespace parapm::cli
