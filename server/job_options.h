// A job's options as the API gives them (parapm.v1.JobOptions, every field optional) and as
// the engine takes them: defaults filled in, every field checked, with messages that name
// the field and its range.
#pragma once

#include "parallel/parallel_build.h"
#include "parapm.pb.h"
#include "simplify/simplify.h"

namespace parapm::service {

struct JobSpec {
  SimplifyOptions simplify;
  ParallelOptions parallel;
};

// Throws Error(kInvalidInput) naming the bad field. `default_parallelism` is used when the
// options leave p at 0.
JobSpec job_spec_of(const parapm::v1::JobOptions& options, uint32_t default_parallelism);

}  // namespace parapm::service
