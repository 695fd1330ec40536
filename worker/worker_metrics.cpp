#include "worker_metrics.h"

namespace parapm::worker {

WorkerMetrics::WorkerMetrics(unsigned slot_count)
    : registry(std::make_shared<prometheus::Registry>()),
      subsets(prometheus::BuildCounter()
                  .Name("parapm_worker_subsets_total")
                  .Help("Subset calls ended, by outcome (done, failed, cancelled)")
                  .Register(*registry)),
      subset_seconds(
          prometheus::BuildHistogram()
              .Name("parapm_worker_subset_seconds")
              .Help("Seconds of a subset call done, from its start to its summary sent")
              .Register(*registry)
              .Add({}, prometheus::Histogram::BucketBoundaries{0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1,
                                                               2.5, 5, 10, 25, 50, 100, 250, 500})),
      job_bytes(prometheus::BuildCounter()
                    .Name("parapm_worker_job_bytes_total")
                    .Help("Bytes of subset jobs received")
                    .Register(*registry)
                    .Add({})),
      result_bytes(prometheus::BuildCounter()
                       .Name("parapm_worker_result_bytes_total")
                       .Help("Bytes of records and summaries sent")
                       .Register(*registry)
                       .Add({})),
      slots(prometheus::BuildGauge()
                .Name("parapm_worker_slots")
                .Help("Subsets this worker runs at once (--threads)")
                .Register(*registry)
                .Add({})),
      running(prometheus::BuildGauge()
                  .Name("parapm_worker_subsets_running")
                  .Help("Subsets running now")
                  .Register(*registry)
                  .Add({})),
      held_state_bytes(prometheus::BuildGauge()
                           .Name("parapm_worker_held_state_bytes")
                           .Help("Bytes of state kept between builds' rounds "
                                 "(--held-state-mb bounds them)")
                           .Register(*registry)
                           .Add({})) {
  for (const char* outcome : {"done", "failed", "cancelled"}) subsets.Add({{"outcome", outcome}});
  slots.Set(double(slot_count));
}

}  // namespace parapm::worker
