// The coordinator's Prometheus metrics (served at /metrics on its viewer's port; names and
// meanings in docs/OPERATIONS.md). Counters and the histogram are updated where their events
// happen; the gauges of state (jobs by state, queue depth, registered workers) are read from
// the coordinator just before a scrape (Coordinator::refresh_metrics). Thread-safe.
#pragma once

#include <memory>

#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

namespace parapm::service {

struct CoordinatorMetrics {
  CoordinatorMetrics();

  std::shared_ptr<prometheus::Registry> registry;
  prometheus::Family<prometheus::Gauge>& jobs;  // {state}: stored jobs
  prometheus::Gauge& queue_depth;
  prometheus::Gauge& workers_registered;
  prometheus::Family<prometheus::Counter>& jobs_ended;  // {state}: done, failed, cancelled
  prometheus::Histogram& job_build_seconds;             // jobs done: start to PM stored
  prometheus::Counter& subsets_dispatched;              // subset calls started (retries too)
  prometheus::Counter& subsets_retried;
  prometheus::Counter& subset_job_bytes;     // sent to workers
  prometheus::Counter& subset_result_bytes;  // received from workers
  prometheus::Counter& uploads_accepted;
  prometheus::Counter& upload_bytes;                         // accepted uploads, as sent
  prometheus::Family<prometheus::Counter>& uploads_refused;  // {reason}
};

}  // namespace parapm::service
