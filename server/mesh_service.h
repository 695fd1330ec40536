// MeshService bridge: converts requests, calls the Coordinator, converts results and errors
// (rpc::serve). Every call is admitted first, streaming calls by `streams` (bounded in number,
// idle time and age), unary calls by `unary` (bounded in number); streams stop cleanly when a
// write fails (the client went away).
#pragma once

#include "call_admission.h"
#include "coordinator.h"
#include "parapm.grpc.pb.h"
#include "rpc_security.h"

namespace parapm::service {

class MeshService final : public parapm::v1::MeshService::Service {
 public:
  MeshService(Coordinator& coordinator, rpc::TokenCheck auth, rpc::CallAdmission& streams,
              rpc::CallAdmission& unary)
      : coordinator_(coordinator), auth_(std::move(auth)), streams_(streams), unary_(unary) {}

  grpc::Status Upload(grpc::ServerContext* context,
                      grpc::ServerReader<parapm::v1::UploadChunk>* reader,
                      parapm::v1::UploadReply* reply) override;
  grpc::Status Submit(grpc::ServerContext* context, const parapm::v1::SubmitRequest* request,
                      parapm::v1::Job* reply) override;
  grpc::Status Watch(grpc::ServerContext* context, const parapm::v1::WatchRequest* request,
                     grpc::ServerWriter<parapm::v1::JobEvent>* writer) override;
  grpc::Status GetJob(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                      parapm::v1::Job* reply) override;
  grpc::Status ListJobs(grpc::ServerContext* context, const parapm::v1::ListJobsRequest* request,
                        parapm::v1::ListJobsReply* reply) override;
  grpc::Status CancelJob(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                         parapm::v1::Job* reply) override;
  grpc::Status DeleteJob(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                         parapm::v1::DeleteReply* reply) override;
  grpc::Status DeleteMesh(grpc::ServerContext* context, const parapm::v1::MeshRef* request,
                          parapm::v1::DeleteReply* reply) override;
  grpc::Status Download(grpc::ServerContext* context, const parapm::v1::JobRef* request,
                        grpc::ServerWriter<parapm::v1::Chunk>* writer) override;
  grpc::Status GetLevel(grpc::ServerContext* context, const parapm::v1::LevelRequest* request,
                        grpc::ServerWriter<parapm::v1::Chunk>* writer) override;
  grpc::Status StreamPM(grpc::ServerContext* context, const parapm::v1::StreamRequest* request,
                        grpc::ServerWriter<parapm::v1::PmStreamMessage>* writer) override;

 private:
  // The upload's outcome in the metrics: accepted (with its bytes), or refused and why.
  void count_upload(const grpc::Status& status, bool admitted, uint64_t bytes_sent);

  Coordinator& coordinator_;
  rpc::TokenCheck auth_;
  rpc::CallAdmission& streams_;
  rpc::CallAdmission& unary_;
};

}  // namespace parapm::service
