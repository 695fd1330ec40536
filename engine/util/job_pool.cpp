#include "util/job_pool.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

namespace parapm {

unsigned pool_threads(unsigned threads, size_t jobs) {
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  if (threads == 0 || threads > hardware) threads = hardware;
  return unsigned(std::max<size_t>(1, std::min<size_t>(threads, jobs)));
}

void run_jobs(size_t jobs, unsigned threads, const std::function<void(size_t)>& work) {
  if (jobs == 0) return;
  const unsigned count = pool_threads(threads, jobs);
  std::vector<std::exception_ptr> errors(jobs);
  std::atomic<size_t> next{0};
  auto drain = [&] {
    for (size_t i = next++; i < jobs; i = next++) {
      try {
        work(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(count);
  for (unsigned t = 0; t < count; ++t) pool.emplace_back(drain);
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace parapm
