// Wall-clock seconds for the timings the programs report.
#pragma once

#include <chrono>

namespace parapm {

inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace parapm
