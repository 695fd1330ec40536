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

constexpr uint32_t kMaxParallelism = 256;
// The smallest subset worth a call: a subset of fewer faces is mostly border, and its round
// costs calls and stored events for next to no collapses. Jobs are held to it.
constexpr uint64_t kLeastSubsetFaces = 50;
// The largest p a mesh of `faces` faces can use: one subset per kLeastSubsetFaces faces.
uint32_t most_useful_parallelism(uint64_t faces);

// Throws Error(kInvalidInput) naming the bad field. `default_parallelism` is used when the
// options leave p at 0.
JobSpec job_spec_of(const parapm::v1::JobOptions& options, uint32_t default_parallelism);

}  // namespace parapm::service
