// JSON of the API's messages for --json output: the protobuf's own JSON mapping, with the
// .proto's field names.
#pragma once

#include <nlohmann/json.hpp>

#include "parapm.pb.h"

namespace parapm::cli {

nlohmann::json message_json(const google::protobuf::Message& message);
nlohmann::json job_json(const parapm::v1::Job& job);

}  // namespace parapm::cli
