// A worker's Prometheus metrics (parapm-worker --metrics-listen; names and meanings in
// docs/OPERATIONS.md): subsets by outcome, their seconds, bytes in and out, slots in use.
// Thread-safe.
#pragma once

#include <memory>

#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

namespace parapm::worker {

struct WorkerMetrics {
  explicit WorkerMetrics(unsigned slots);

  std::shared_ptr<prometheus::Registry> registry;
  prometheus::Family<prometheus::Counter>& subsets;  // {outcome}: done, failed, cancelled
  prometheus::Histogram& subset_seconds;             // subsets done: call start to summary sent
  prometheus::Counter& job_bytes;                    // subset jobs received
  prometheus::Counter& result_bytes;                 // records and summaries sent
  prometheus::Gauge& slots;                          // --threads
  prometheus::Gauge& running;                        // subsets running now
  prometheus::Gauge& held_state_bytes;               // HeldStateCache::bytes()
};

}  // namespace parapm::worker
