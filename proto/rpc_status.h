// The one mapping between the engine's errors and gRPC status codes, both ways, and the
// bridge every RPC handler runs through (STYLE.md, "gRPC services": thin bridges, one status
// mapping).
#pragma once

#include <exception>
#include <functional>
#include <string>

#include <grpcpp/grpcpp.h>

#include "util/error.h"

namespace parapm::rpc {

grpc::StatusCode status_code_of(ErrorCode code);
// "INVALID_ARGUMENT", ... as the gRPC docs spell them.
const char* status_code_name(grpc::StatusCode code);
ErrorCode error_code_of(grpc::StatusCode code);

// The status of the exception in flight (parapm::Error by its code; std::bad_alloc:
// RESOURCE_EXHAUSTED; anything else: INTERNAL). Call from a catch block only.
grpc::Status status_of_current_exception();

// Throws the Error a failed status stands for ("<what>: <status message>"); does nothing
// for OK. Clients of the API use it to turn a failed call into the engine's error.
void throw_if_failed(const grpc::Status& status, const std::string& what);

}  // namespace parapm::rpc
