// Any bytes as what a worker or the coordinator decodes: the first byte picks a subset job, a
// batch of collapse records or a subset summary. Every outcome must be a value or a
// parapm::Error.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "parallel/job_codec.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    switch (data[0] % 3) {
      case 0:
        parapm::decode_subset_job(bytes);
        break;
      case 1: {
        std::vector<parapm::CollapseRecord> records;
        parapm::decode_collapse_records(bytes, records);
        break;
      }
      default: {
        parapm::SubsetResult result;
        parapm::decode_subset_summary(bytes, result);
      }
    }
  } catch (const parapm::Error&) {
  }
  return 0;
}
