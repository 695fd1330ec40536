#include "coordinator_metrics.h"

namespace parapm::service {
namespace {

// Build times from a small mesh on many cores (0.1 s) to a huge one on a few (an hour).
prometheus::Histogram::BucketBoundaries build_seconds_buckets() {
  return {0.1, 0.25, 0.5, 1, 2.5, 5, 10, 25, 50, 100, 250, 500, 1000, 2500};
}

}  // namespace

CoordinatorMetrics::CoordinatorMetrics()
    : registry(std::make_shared<prometheus::Registry>()),
      jobs(prometheus::BuildGauge()
               .Name("parapm_jobs")
               .Help("Stored jobs by state (queued, running, done, failed, cancelled)")
               .Register(*registry)),
      queue_depth(prometheus::BuildGauge()
                      .Name("parapm_queue_depth")
                      .Help("Jobs waiting for a build slot (--max-running-jobs)")
                      .Register(*registry)
                      .Add({})),
      workers_registered(prometheus::BuildGauge()
                             .Name("parapm_workers_registered")
                             .Help("Workers registered and beating")
                             .Register(*registry)
                             .Add({})),
      jobs_ended(prometheus::BuildCounter()
                     .Name("parapm_jobs_ended_total")
                     .Help("Jobs ended since the coordinator started, by final state")
                     .Register(*registry)),
      job_build_seconds(prometheus::BuildHistogram()
                            .Name("parapm_job_build_seconds")
                            .Help("Seconds from a job's start to its PM stored, jobs done")
                            .Register(*registry)
                            .Add({}, build_seconds_buckets())),
      subsets_dispatched(prometheus::BuildCounter()
                             .Name("parapm_subsets_dispatched_total")
                             .Help("Subset calls started, to workers or in-process, retries too")
                             .Register(*registry)
                             .Add({})),
      subsets_retried(prometheus::BuildCounter()
                          .Name("parapm_subsets_retried_total")
                          .Help("Subsets dispatched again after their worker died or failed")
                          .Register(*registry)
                          .Add({})),
      subset_job_bytes(prometheus::BuildCounter()
                           .Name("parapm_subset_job_bytes_total")
                           .Help("Bytes of subset jobs sent to workers")
                           .Register(*registry)
                           .Add({})),
      subset_result_bytes(prometheus::BuildCounter()
                              .Name("parapm_subset_result_bytes_total")
                              .Help("Bytes of records and summaries received from workers")
                              .Register(*registry)
                              .Add({})),
      uploads_accepted(prometheus::BuildCounter()
                           .Name("parapm_uploads_accepted_total")
                           .Help("Uploads stored as meshes (or found stored already)")
                           .Register(*registry)
                           .Add({})),
      upload_bytes(prometheus::BuildCounter()
                       .Name("parapm_upload_bytes_total")
                       .Help("Bytes of accepted uploads, as sent")
                       .Register(*registry)
                       .Add({})),
      uploads_refused(prometheus::BuildCounter()
                          .Name("parapm_uploads_refused_total")
                          .Help("Uploads refused, by reason (unauthenticated, busy, too_large, "
                                "invalid, cut_off, error)")
                          .Register(*registry)) {
  for (const char* state : {"done", "failed", "cancelled"}) jobs_ended.Add({{"state", state}});
}

}  // namespace parapm::service
