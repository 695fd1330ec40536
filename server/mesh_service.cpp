#include "mesh_service.h"

#include <cmath>
#include <fstream>

#include <spdlog/spdlog.h>

#include "io/mesh_io.h"
#include "pm/levels.h"
#include "rpc_server.h"
#include "storage/ids.h"
#include "util/error.h"

namespace parapm::service {
namespace {

constexpr size_t kChunkBytes = 1 << 20;
const grpc::Status kClientGone(grpc::StatusCode::CANCELLED, "the client went away");

void require_id(const std::string& id, const char* what) {
  if (id.empty() || id.size() > 64) throw_invalid(std::string(what) + " must be given");
}

// How a stream that stopped ends: the watchdog's reason when it closed it, else the client left.
grpc::Status stopped(const rpc::CallAdmission::Ticket& ticket) {
  return ticket.expired().value_or(kClientGone);
}

// Sends `bytes` in chunks; false when the client went away.
bool send_chunks(grpc::ServerWriter<parapm::v1::Chunk>* writer, std::string_view bytes,
                 rpc::CallAdmission::Ticket& ticket) {
  parapm::v1::Chunk chunk;
  chunk.set_total(bytes.size());
  ticket.touch();  // the work is done: from here the idle clock waits on the client
  for (size_t at = 0; at < bytes.size() || at == 0; at += kChunkBytes) {
    chunk.set_offset(at);
    chunk.set_data(std::string(bytes.substr(at, kChunkBytes)));
    if (!writer->Write(chunk)) return false;
    ticket.touch();
    if (bytes.empty()) break;
  }
  return true;
}

bool terminal(const parapm::v1::JobEvent& event) {
  return event.has_finished() || event.has_failed() || event.has_cancelled();
}

}  // namespace

grpc::Status MeshService::Upload(grpc::ServerContext* context,
                                 grpc::ServerReader<parapm::v1::UploadChunk>* reader,
                                 parapm::v1::UploadReply* reply) {
  bool admitted = false;
  uint64_t bytes_sent = 0;
  const grpc::Status status = rpc::serve(auth_, context, [&] {
    grpc::Status refused;
    const auto ticket = streams_.admit(context, "Upload", &refused);
    if (!ticket) return refused;
    admitted = true;
    parapm::v1::UploadChunk chunk;
    if (!reader->Read(&chunk)) {
      if (auto expired = ticket->expired()) return *expired;
      throw_invalid("the upload has no chunk (send the file name first)");
    }
    service::Upload upload = coordinator_.begin_upload(chunk.file_name());
    do {
      // Storing a chunk (a large upload's buffer grows, its pages fresh) is the server's work:
      // the idle clock waits on the client from after it.
      ticket->working();
      upload.add(chunk.data());
      ticket->touch();
    } while (reader->Read(&chunk));
    if (auto expired = ticket->expired()) return *expired;
    if (context->IsCancelled()) return grpc::Status(grpc::StatusCode::CANCELLED, "upload cut off");
    ticket->working();  // parsing a large mesh may take longer than the idle limit
    bytes_sent = upload.size();
    const UploadResult result = coordinator_.finish_upload(std::move(upload));
    reply->set_mesh_id(result.mesh.mesh_id);
    reply->set_content_sha256(result.mesh.sha256);
    reply->set_bytes(result.mesh.bytes);
    reply->set_vertices(result.mesh.vertices);
    reply->set_faces(result.mesh.faces);
    reply->set_repairs(result.repairs);
    return grpc::Status::OK;
  });
  count_upload(status, admitted, bytes_sent);
  return status;
}

void MeshService::count_upload(const grpc::Status& status, bool admitted, uint64_t bytes_sent) {
  CoordinatorMetrics& metrics = coordinator_.metrics();
  if (status.ok()) {
    metrics.uploads_accepted.Increment();
    metrics.upload_bytes.Increment(double(bytes_sent));
    return;
  }
  const char* reason = "error";
  switch (status.error_code()) {
    case grpc::StatusCode::UNAUTHENTICATED:
      reason = "unauthenticated";
      break;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      reason = admitted ? "too_large" : "busy";
      break;
    case grpc::StatusCode::INVALID_ARGUMENT:
      reason = "invalid";
      break;
    case grpc::StatusCode::CANCELLED:
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      reason = "cut_off";
      break;
    default:
      break;
  }
  metrics.uploads_refused.Add({{"reason", reason}}).Increment();
}

grpc::Status MeshService::Submit(grpc::ServerContext* context,
                                 const parapm::v1::SubmitRequest* request, parapm::v1::Job* reply) {
  return rpc::serve(auth_, context, [&] {
    grpc::Status refused;
    const auto ticket = unary_.admit(context, "Submit", &refused);
    if (!ticket) return refused;
    require_id(request->mesh_id(), "mesh_id");
    *reply = coordinator_.submit(request->mesh_id(), request->options());
    return grpc::Status::OK;
  });
}

grpc::Status MeshService::Watch(grpc::ServerContext* context,
                                const parapm::v1::WatchRequest* request,
                                grpc::ServerWriter<parapm::v1::JobEvent>* writer) {
  return rpc::serve(auth_, context, [&] {
    require_id(request->job_id(), "job_id");
    grpc::Status refused;
    const auto ticket = streams_.admit(context, "Watch", &refused);
    if (!ticket) return refused;
    uint64_t after = request->after_seq();
    while (!context->IsCancelled()) {
      if (ticket->past_total())
        return grpc::Status(
            grpc::StatusCode::DEADLINE_EXCEEDED,
            "watch open for its longest time: watch again from after_seq " + std::to_string(after));
      const std::vector<parapm::v1::JobEvent> events =
          coordinator_.events(request->job_id(), after, std::chrono::milliseconds(500));
      ticket->touch();  // waiting for events is not idling; a blocked Write is
      for (const parapm::v1::JobEvent& event : events) {
        if (!writer->Write(event)) return stopped(*ticket);
        ticket->touch();
        after = event.seq();
        if (terminal(event)) return grpc::Status::OK;
      }
      if (!events.empty()) continue;
      // Quiet: a job that finished before this watch's `after_seq` sends nothing more.
      const parapm::v1::Job job = coordinator_.job(request->job_id());
      if (job.state() == parapm::v1::DONE || job.state() == parapm::v1::FAILED ||
          job.state() == parapm::v1::CANCELLED) {
        if (coordinator_.events(request->job_id(), after, std::chrono::milliseconds(0)).empty())
          return grpc::Status::OK;
      }
    }
    return ticket->expired().value_or(grpc::Status(grpc::StatusCode::CANCELLED, "watch cancelled"));
  });
}

grpc::Status MeshService::GetJob(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                                 parapm::v1::Job* reply) {
  return rpc::serve(auth_, context, [&] {
    grpc::Status refused;
    const auto ticket = unary_.admit(context, "GetJob", &refused);
    if (!ticket) return refused;
    require_id(request->job_id(), "job_id");
    *reply = coordinator_.job(request->job_id());
    return grpc::Status::OK;
  });
}

grpc::Status MeshService::ListJobs(grpc::ServerContext* context,
                                   const parapm::v1::ListJobsRequest* request,
                                   parapm::v1::ListJobsReply* reply) {
  return rpc::serve(auth_, context, [&] {
    grpc::Status refused;
    const auto ticket = unary_.admit(context, "ListJobs", &refused);
    if (!ticket) return refused;
    const size_t limit = request->limit() ? std::min<uint32_t>(request->limit(), 10000) : 100;
    for (parapm::v1::Job& job : coordinator_.jobs(limit)) *reply->add_jobs() = std::move(job);
    return grpc::Status::OK;
  });
}

grpc::Status MeshService::CancelJob(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                                    parapm::v1::Job* reply) {
  return rpc::serve(auth_, context, [&] {
    grpc::Status refused;
    const auto ticket = unary_.admit(context, "CancelJob", &refused);
    if (!ticket) return refused;
    require_id(request->job_id(), "job_id");
    *reply = coordinator_.cancel(request->job_id());
    return grpc::Status::OK;
  });
}

namespace {

void to_reply(const DeleteResult& result, parapm::v1::DeleteReply* reply) {
  reply->set_jobs_deleted(result.jobs);
  reply->set_meshes_deleted(result.meshes);
  reply->set_blobs_removed(result.blobs);
  reply->set_bytes_freed(result.bytes);
}

}  // namespace

grpc::Status MeshService::DeleteJob(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                                    parapm::v1::DeleteReply* reply) {
  return rpc::serve(auth_, context, [&] {
    grpc::Status refused;
    const auto ticket = unary_.admit(context, "DeleteJob", &refused);
    if (!ticket) return refused;
    require_id(request->job_id(), "job_id");
    to_reply(coordinator_.delete_job(request->job_id()), reply);
    return grpc::Status::OK;
  });
}

grpc::Status MeshService::DeleteMesh(grpc::ServerContext* context,
                                     const parapm::v1::MeshRef* request,
                                     parapm::v1::DeleteReply* reply) {
  return rpc::serve(auth_, context, [&] {
    grpc::Status refused;
    const auto ticket = unary_.admit(context, "DeleteMesh", &refused);
    if (!ticket) return refused;
    require_id(request->mesh_id(), "mesh_id");
    to_reply(coordinator_.delete_mesh(request->mesh_id()), reply);
    return grpc::Status::OK;
  });
}

grpc::Status MeshService::Download(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                                   grpc::ServerWriter<parapm::v1::Chunk>* writer) {
  return rpc::serve(auth_, context, [&] {
    require_id(request->job_id(), "job_id");
    grpc::Status refused;
    const auto ticket = streams_.admit(context, "Download", &refused);
    if (!ticket) return refused;
    ticket->working();  // loading (reading, hashing, decoding) a large PM
    const auto loaded = coordinator_.pm(request->job_id());  // its hash checked
    if (!send_chunks(writer, loaded->bytes, *ticket)) return stopped(*ticket);
    return grpc::Status::OK;
  });
}

grpc::Status MeshService::GetLevel(grpc::ServerContext* context,
                                   const parapm::v1::LevelRequest* request,
                                   grpc::ServerWriter<parapm::v1::Chunk>* writer) {
  return rpc::serve(auth_, context, [&] {
    require_id(request->job_id(), "job_id");
    grpc::Status refused;
    const auto ticket = streams_.admit(context, "GetLevel", &refused);
    if (!ticket) return refused;
    ticket->working();  // loading the PM and cutting the level
    const std::string format = request->format().empty() ? "obj" : request->format();
    if (format != "obj" && format != "ply") throw_invalid("format must be \"obj\" or \"ply\"");
    if (request->cut_case() == parapm::v1::LevelRequest::CUT_NOT_SET)
      throw_invalid("give max_faces or max_error");
    if (request->cut_case() == parapm::v1::LevelRequest::kMaxError &&
        !std::isfinite(request->max_error()))
      throw_invalid("max_error must be finite");
    const auto loaded = coordinator_.pm(request->job_id());
    const size_t level = request->cut_case() == parapm::v1::LevelRequest::kMaxFaces
                             ? level_for_faces(loaded->pm, request->max_faces())
                             : level_for_error(loaded->pm, request->max_error());
    const Mesh mesh = level_of_detail(loaded->pm, level);
    // The writers write files: one in the data folder's temp space, removed at once.
    const std::filesystem::path temp =
        coordinator_.config().data_dir / "blobs" / "tmp" / (new_id("level-") + "." + format);
    std::string bytes;
    try {
      write_mesh(mesh, temp.string());
      std::ifstream in(temp, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    } catch (...) {
      std::filesystem::remove(temp);
      throw;
    }
    std::filesystem::remove(temp);
    if (!send_chunks(writer, bytes, *ticket)) return stopped(*ticket);
    return grpc::Status::OK;
  });
}

grpc::Status MeshService::StreamPM(grpc::ServerContext* context,
                                   const parapm::v1::StreamRequest* request,
                                   grpc::ServerWriter<parapm::v1::PmStreamMessage>* writer) {
  return rpc::serve(auth_, context, [&] {
    require_id(request->job_id(), "job_id");
    grpc::Status refused;
    const auto ticket = streams_.admit(context, "StreamPM", &refused);
    if (!ticket) return refused;
    ticket->working();  // loading the PM
    const auto loaded = coordinator_.pm(request->job_id());
    const uint64_t n = loaded->pm.splits.size();
    uint64_t end = n;
    if (request->until_case() == parapm::v1::StreamRequest::kMaxFaces)
      end = level_for_faces(loaded->pm, request->max_faces());
    else if (request->until_case() == parapm::v1::StreamRequest::kMaxError) {
      if (!std::isfinite(request->max_error())) throw_invalid("max_error must be finite");
      end = level_for_error(loaded->pm, request->max_error());
    }
    if (request->from_vsplit() > n)
      throw_invalid("from_vsplit " + std::to_string(request->from_vsplit()) + " is past the PM's " +
                    std::to_string(n) + " vsplits");
    const uint32_t batch =
        request->batch_vsplits() ? std::min(request->batch_vsplits(), 1u << 20) : 4096u;
    parapm::v1::PmStreamMessage message;
    message.set_total_vsplits(n);
    ticket->touch();  // the PM is loaded: from here the idle clock waits on the client
    if (request->from_vsplit() == 0) {
      message.set_header_and_base(loaded->bytes.substr(0, loaded->splits_begin));
      message.set_first_vsplit(0);
      message.set_count(0);
      if (!writer->Write(message)) return stopped(*ticket);
      ticket->touch();
    }
    for (uint64_t first = request->from_vsplit(); first < end; first += batch) {
      const uint64_t last = std::min<uint64_t>(end, first + batch);
      message.set_vsplit_batch(loaded->bytes.substr(
          loaded->split_begin[first], loaded->split_begin[last] - loaded->split_begin[first]));
      message.set_first_vsplit(first);
      message.set_count(uint32_t(last - first));
      if (!writer->Write(message)) return stopped(*ticket);
      ticket->touch();
    }
    return grpc::Status::OK;
  });
}

}  // namespace parapm::service
