// Any bytes as what a worker or the coordinator decodes: the first byte picks a subset job, a
// batch of collapse records, a subset summary, or a job that leaves out held state (a 2-byte
// little-endian length, that many bytes of the held items' ids, then the job), whose held items
// are then put back as a worker puts back what it holds. Every outcome must be a value or a
// parapm::Error.
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "parallel/held_state.h"
#include "parallel/job_codec.h"
#include "util/error.h"

namespace {

// As the worker does (worker/subset_service.cpp), with zeros for what its cache would give.
void put_back_zeros(parapm::SubsetJob& job, const std::vector<uint32_t>& held) {
  if (held.empty()) return;
  if (job.state.metric == "quadric") {
    parapm::put_back_held_quadrics(job.state.quadric, held,
                                   std::vector<parapm::Quadric>(held.size()));
  } else if (job.state.metric == "energy" && job.state.energy.positions) {
    parapm::EnergyState& state = job.state.energy;
    const size_t k = state.points.empty() ? 0 : state.point_values.size() / state.points.size();
    for (uint32_t i : held)
      if (i >= state.points.size()) return;
    parapm::put_back_held_points(state, held, std::vector<parapm::HeldPoint>(held.size()),
                                 std::vector<float>(held.size() * k));
  }
}

void decode_held_job(std::string_view bytes) {
  if (bytes.size() < 2) return;
  const size_t length = uint8_t(bytes[0]) | size_t(uint8_t(bytes[1])) << 8;
  if (bytes.size() - 2 < length) return;
  const std::vector<uint32_t> held =
      parapm::decode_increasing_ids(bytes.substr(2, length), parapm::kNoId, "held ids");
  parapm::SubsetJob job = parapm::decode_subset_job(bytes.substr(2 + length), held);
  put_back_zeros(job, held);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    switch (data[0] % 4) {
      case 0:
        parapm::decode_subset_job(bytes);
        break;
      case 1: {
        std::vector<parapm::CollapseRecord> records;
        parapm::decode_collapse_records(bytes, records);
        break;
      }
      case 2: {
        parapm::SubsetResult result;
        parapm::decode_subset_summary(bytes, result);
        break;
      }
      default:
        decode_held_job(bytes);
    }
  } catch (const parapm::Error&) {
  }
  return 0;
}
