#include <parapm/client.h>

#include <cstdlib>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "rpc_security.h"
#include "rpc_status.h"
#include "util/error.h"

namespace parapm::client {
namespace {

constexpr size_t kUploadChunkBytes = 1 << 20;

}  // namespace

void check_status(const grpc::Status& status, const std::string& what, const std::string& server) {
  if (status.ok()) return;
  std::string message =
      what + ": " + rpc::status_code_name(status.error_code()) + ": " + status.error_message();
  if (status.error_code() == grpc::StatusCode::UNAVAILABLE)
    message += " (is a coordinator running at " + server + "? 'parapm up' starts one)";
  throw Error(rpc::error_code_of(status.error_code()), message);
}

ServiceClient::ServiceClient(const ConnectionOptions& args) {
  server_ = args.server;
  if (server_.empty()) {
    const char* env = std::getenv("PARAPM_SERVER");
    server_ = env && *env ? env : kDefaultServer;
  }
  token_ = rpc::load_token(args.token_file);
  rpc::TlsFiles files;
  files.ca_file = args.tls_ca;
  stub_ = parapm::v1::MeshService::NewStub(
      rpc::make_channel(server_, rpc::channel_credentials(args.tls, files)));
}

std::unique_ptr<grpc::ClientContext> ServiceClient::context(double timeout_s) const {
  auto context = std::make_unique<grpc::ClientContext>();
  rpc::attach_token(*context, token_);
  if (timeout_s > 0)
    context->set_deadline(std::chrono::system_clock::now() +
                          std::chrono::milliseconds(int64_t(timeout_s * 1000)));
  return context;
}

parapm::v1::UploadReply ServiceClient::upload(
    const std::filesystem::path& path, const std::function<void(uint64_t, uint64_t)>& progress) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kNotFound, path.string() + ": cannot open");
  const uint64_t total = std::filesystem::file_size(path);
  auto context = this->context(0);
  parapm::v1::UploadReply reply;
  auto writer = stub_->Upload(context.get(), &reply);
  parapm::v1::UploadChunk chunk;
  chunk.set_file_name(path.filename().string());
  std::string buffer(kUploadChunkBytes, '\0');
  uint64_t sent = 0;
  do {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    chunk.set_data(buffer.data(), size_t(in.gcount()));
    // A failed write means the server ended the call (e.g. over its size limit): Finish says why.
    if (!writer->Write(chunk)) break;
    sent += uint64_t(in.gcount());
    chunk.clear_file_name();
    if (progress) progress(sent, total);
  } while (in);
  writer->WritesDone();
  check_status(writer->Finish(), "upload " + path.string(), server_);
  return reply;
}

parapm::v1::Job ServiceClient::watch(
    const std::string& job_id, const std::function<void(const parapm::v1::JobEvent&)>& on_event) {
  uint64_t after = 0;
  // A watch that breaks (the coordinator restarted, closed a watch open for its longest time,
  // or had no room for another stream) resumes after the last event seen.
  for (int attempt = 0;; ++attempt) {
    auto context = this->context(0);
    parapm::v1::WatchRequest request;
    request.set_job_id(job_id);
    request.set_after_seq(after);
    auto reader = stub_->Watch(context.get(), request);
    parapm::v1::JobEvent event;
    while (reader->Read(&event)) {
      after = event.seq();
      attempt = 0;
      if (on_event) on_event(event);
    }
    const grpc::Status status = reader->Finish();
    if (status.ok()) break;
    const grpc::StatusCode code = status.error_code();
    const bool resumable = code == grpc::StatusCode::UNAVAILABLE ||
                           code == grpc::StatusCode::DEADLINE_EXCEEDED ||
                           code == grpc::StatusCode::RESOURCE_EXHAUSTED;
    if (!resumable || attempt >= 60) check_status(status, "watch " + job_id, server_);
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  auto context = this->context();
  parapm::v1::JobRef ref;
  ref.set_job_id(job_id);
  parapm::v1::Job job;
  check_status(stub_->GetJob(context.get(), ref, &job), "get job " + job_id, server_);
  return job;
}

uint64_t ServiceClient::receive_file(grpc::ClientReader<parapm::v1::Chunk>& reader,
                                     const std::filesystem::path& out, const std::string& what) {
  const std::filesystem::path temp = out.string() + ".part";
  uint64_t written = 0;
  {
    std::ofstream file(temp, std::ios::binary | std::ios::trunc);
    if (!file) throw Error(ErrorCode::kIo, out.string() + ": cannot write");
    parapm::v1::Chunk chunk;
    while (reader.Read(&chunk)) {
      file.write(chunk.data().data(), std::streamsize(chunk.data().size()));
      written += chunk.data().size();
    }
    const grpc::Status status = reader.Finish();
    if (!status.ok()) {
      file.close();
      std::filesystem::remove(temp);
      check_status(status, what, server_);
    }
    file.flush();
    if (!file) throw Error(ErrorCode::kIo, out.string() + ": write failed (disk full?)");
  }
  std::filesystem::rename(temp, out);
  return written;
}

parapm::v1::Job ServiceClient::submit(const std::string& mesh_id,
                                      const parapm::v1::JobOptions& options) {
  auto context = this->context();
  parapm::v1::SubmitRequest request;
  request.set_mesh_id(mesh_id);
  *request.mutable_options() = options;
  parapm::v1::Job job;
  check_status(stub_->Submit(context.get(), request, &job), "submit " + mesh_id, server_);
  return job;
}

uint64_t ServiceClient::stream(
    const parapm::v1::StreamRequest& request,
    const std::function<void(const parapm::v1::PmStreamMessage&)>& on_message) {
  auto context = this->context(0);
  auto reader = stub_->StreamPM(context.get(), request);
  parapm::v1::PmStreamMessage message;
  uint64_t received = 0;
  while (reader->Read(&message)) {
    ++received;
    if (on_message) on_message(message);
  }
  check_status(reader->Finish(), "stream " + request.job_id(), server_);
  return received;
}

uint64_t ServiceClient::download(const std::string& job_id, const std::filesystem::path& out) {
  auto context = this->context(0);
  parapm::v1::JobRef ref;
  ref.set_job_id(job_id);
  auto reader = stub_->Download(context.get(), ref);
  return receive_file(*reader, out, "download " + job_id);
}

const char* job_state_name(parapm::v1::JobState state) {
  switch (state) {
    case parapm::v1::QUEUED:
      return "queued";
    case parapm::v1::RUNNING:
      return "running";
    case parapm::v1::DONE:
      return "done";
    case parapm::v1::FAILED:
      return "failed";
    case parapm::v1::CANCELLED:
      return "cancelled";
    default:
      return "unknown";
  }
}

std::string describe_event(const parapm::v1::JobEvent& e) {
  switch (e.event_case()) {
    case parapm::v1::JobEvent::kQueued:
      return "queued";
    case parapm::v1::JobEvent::kStarted:
      return fmt::format("started (attempt {}): {} faces -> {}", e.started().attempt(),
                         e.started().input_faces(),
                         e.started().target_faces() ? std::to_string(e.started().target_faces())
                                                    : std::string("as few as legal"));
    case parapm::v1::JobEvent::kPartitioned:
      return fmt::format("round {}: {} faces partitioned into {} subsets", e.partitioned().round(),
                         e.partitioned().faces(), e.partitioned().subsets());
    case parapm::v1::JobEvent::kSubsetStarted:
      return fmt::format("round {} subset {}: started on {}{}", e.subset_started().round(),
                         e.subset_started().subset(), e.subset_started().worker(),
                         e.subset_started().attempt() > 1
                             ? fmt::format(" (attempt {})", e.subset_started().attempt())
                             : "");
    case parapm::v1::JobEvent::kSubsetDone:
      return fmt::format("round {} subset {}: {} collapses on {} in {:.3f} s",
                         e.subset_done().round(), e.subset_done().subset(),
                         e.subset_done().collapses(), e.subset_done().worker(),
                         e.subset_done().seconds());
    case parapm::v1::JobEvent::kMerged:
      return fmt::format("round {}: merged in {:.3f} s, {} faces left", e.merged().round(),
                         e.merged().seconds(), e.merged().faces());
    case parapm::v1::JobEvent::kProgress:
      return fmt::format("progress {}/{}", e.progress().done(), e.progress().total());
    case parapm::v1::JobEvent::kFinished:
      return fmt::format("done: base mesh {} faces, {} vsplits, {:.3f} s",
                         e.finished().base_faces(), e.finished().vsplits(), e.finished().seconds());
    case parapm::v1::JobEvent::kFailed:
      return "failed: " + e.failed().reason();
    case parapm::v1::JobEvent::kCancelled:
      return "cancelled";
    default:
      return "event";
  }
}

}  // namespace parapm::client
