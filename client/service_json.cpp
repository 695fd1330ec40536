#include "service_json.h"

#include <google/protobuf/util/json_util.h>

namespace parapm::cli {

nlohmann::json message_json(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  options.always_print_enums_as_ints = false;
  std::string text;
  (void)google::protobuf::util::MessageToJsonString(message, &text, options);
  return nlohmann::json::parse(text);
}

nlohmann::json job_json(const parapm::v1::Job& job) {
  nlohmann::json out = message_json(job);
  // Protobuf's mapping writes 64-bit integers as strings; scripts want numbers.
  for (const char* key : {"input_faces", "base_faces", "vsplits", "created_unix_ms",
                          "updated_unix_ms", "pm_bytes", "progress_done", "progress_total"})
    if (out.contains(key) && out[key].is_string())
      out[key] = std::stoll(out[key].get<std::string>());
  return out;
}

}  // namespace parapm::cli
