// Process memory figures for reports (Linux /proc; 0 where unavailable).
#pragma once

#include <cstdint>
#include <vector>

namespace parapm {

uint64_t peak_memory_bytes();     // high-water mark of the resident set (VmHWM)
uint64_t current_memory_bytes();  // resident set now (VmRSS)

// Gives the memory the allocator holds free back to the system (glibc: malloc_trim; elsewhere
// nothing). The parallel build calls it between its stages: memory its jobs freed on the
// pool's threads stays in those threads' arenas otherwise, and the next stage's allocations,
// on the master's thread, come on top of it.
void release_free_memory();

// Hands the pages wholly inside [begin, end) back to the system (Linux: madvise MADV_DONTNEED;
// elsewhere nothing): memory a block holds but no object lives in. They read as zeros if
// written again.
void release_pages(void* begin, void* end);

// release_pages of v's capacity beyond its size: for a vector kept long after a generous
// reserve, whose unused pages an allocator's reuse may have left resident.
template <class T>
void release_unused_capacity(std::vector<T>& v) {
  release_pages(v.data() + v.size(), v.data() + v.capacity());
}

// Has every block of 1 MiB or more mapped for itself and unmapped when freed (glibc: a fixed
// M_MMAP_THRESHOLD; elsewhere nothing), for the rest of the process. For processes that build
// on a pool of threads: glibc's default raises the threshold to the largest block freed (up to
// 32 MiB), after which a job's large arrays, freed on a pool's thread, stay in that thread's
// arena and the next job's come on top of them. The price: fresh pages for each large block.
void map_large_blocks_alone();

}  // namespace parapm
