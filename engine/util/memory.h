// Process memory figures for reports (Linux /proc; 0 where unavailable).
#pragma once

#include <cstdint>

namespace parapm {

uint64_t peak_memory_bytes();     // high-water mark of the resident set (VmHWM)
uint64_t current_memory_bytes();  // resident set now (VmRSS)

// Gives the memory the allocator holds free back to the system (glibc: malloc_trim; elsewhere
// nothing). The parallel build calls it between its stages: memory its jobs freed on the
// pool's threads stays in those threads' arenas otherwise, and the next stage's allocations,
// on the master's thread, come on top of it.
void release_free_memory();

}  // namespace parapm
