// A fixed pool of std::threads for the subset jobs of one round: job i runs on whichever
// thread takes it first, and its result goes to slot i, so that what the caller sees does not
// depend on the timing.
#pragma once

#include <cstddef>
#include <functional>

namespace parapm {

// Runs work(0) ... work(jobs - 1) on min(threads, jobs) threads (threads 0: one per hardware
// thread) and returns when all are done. The calling thread only waits, so that its CPU time
// is the caller's own. When jobs
// throw, the exception of the lowest job index is rethrown; the other jobs still run (a job
// is expected to poll the caller's CancelToken to stop early).
void run_jobs(size_t jobs, unsigned threads, const std::function<void(size_t)>& work);

// The thread count run_jobs uses for `threads` (0 or more than the hardware: the hardware's).
unsigned pool_threads(unsigned threads, size_t jobs);

}  // namespace parapm
