// What the workers hold of one build's quadrics (engine/parallel/held_quadrics.h), as the
// coordinator knows it: per global vertex, the worker its latest job ran on and the
// fingerprint of the quadric that job left it with (the worker keeps it). A later job of that
// worker leaves out the quadrics whose value on the master has the same fingerprint still.
// Not thread-safe: the dispatching thread's.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "parallel/subset_job.h"

namespace parapm::service {

class HeldQuadricsLedger {
 public:
  // A job's worker, the one holding most of its quadrics among those it may go to (empty:
  // none holds any), and per entry of its state whether that worker holds it.
  struct Plan {
    std::string worker;
    std::vector<uint8_t> held;
    size_t count = 0;
  };
  // The plans of a round's jobs on `slots` (live workers and their slots): each job to the
  // worker holding most of its quadrics, but no worker given more than its share of the
  // round's jobs (slots in proportion, rounded up), the jobs holding the most placed first.
  std::vector<Plan> plan_round(const std::vector<SubsetJob>& jobs,
                               const std::map<std::string, uint32_t>& slots) const;

  // `worker` keeps these quadrics (global vertex id, quadric_fingerprint) now.
  void record(const std::string& worker, const std::vector<std::pair<VertexId, uint64_t>>& kept);

 private:
  // Per entry of the job's state, the worker (1 + index into workers_) holding it unchanged,
  // or 0; and the count per worker (index 0: none).
  void holders(const SubsetJob& job, std::vector<uint32_t>& holder,
               std::vector<size_t>& count) const;
  uint32_t index_of(const std::string& worker);

  std::vector<uint32_t> holder_;  // per global vertex: 1 + index into workers_; 0: none
  std::vector<uint64_t> fingerprint_;
  std::vector<std::string> workers_;
};

}  // namespace parapm::service
