#include "storage/ids.h"

#include <chrono>
#include <random>

namespace parapm::service {

std::string new_id(std::string_view prefix) {
  // A random_device per call: it is not guaranteed to be safe to share between threads, and
  // ids are made once per upload or job, so the cost does not matter.
  std::random_device device;
  const uint64_t bits = (uint64_t{device()} << 32) | uint64_t{device()};
  static constexpr char kHex[] = "0123456789abcdef";
  std::string id(prefix);
  for (int shift = 60; shift >= 0; shift -= 4) id.push_back(kHex[(bits >> shift) & 0xf]);
  return id;
}

int64_t unix_ms_now() {
  using namespace std::chrono;
  return duration_cast<milliseconds>(system_clock::now().time_since_epoch()).count();
}

}  // namespace parapm::service
