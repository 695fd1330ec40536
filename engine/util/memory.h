// Process memory figures for reports (Linux /proc; 0 where unavailable).
#pragma once

#include <cstdint>

namespace parapm {

uint64_t peak_memory_bytes();     // high-water mark of the resident set (VmHWM)
uint64_t current_memory_bytes();  // resident set now (VmRSS)

}  // namespace parapm
