// What the workers hold of one build's state (engine/parallel/held_state.h), as the
// coordinator knows it: per item (a quadric build's global vertices, an energy build's sample
// points), the worker that holds it last and the fingerprint of what it holds. A later job of
// that worker leaves out the items whose value on the master has the same fingerprint still.
// Not thread-safe: the dispatching thread's.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace parapm::service {

class HeldStateLedger {
 public:
  // A job's worker, the one holding most of its items (holdable_items) among those it may go
  // to (empty: none holds any), and per item whether that worker holds it.
  struct Plan {
    std::string worker;
    std::vector<uint8_t> held;
    size_t count = 0;
  };
  // The plans of a round's jobs, given each job's items (holdable_items: id, fingerprint), on
  // `slots` (live workers and their slots): each job to the worker holding most of its items,
  // but no worker given more than its share of the round's jobs (slots in proportion, rounded
  // up), the jobs holding the most placed first.
  using Items = std::vector<std::pair<uint32_t, uint64_t>>;
  std::vector<Plan> plan_round(const std::vector<Items>& jobs,
                               const std::map<std::string, uint32_t>& slots) const;

  // `worker` holds these items (id, fingerprint) now.
  void record(const std::string& worker, const std::vector<std::pair<uint32_t, uint64_t>>& kept);

 private:
  // Per item of the job, the worker (1 + index into workers_) holding it unchanged, or 0; and
  // the count per worker (index 0: none).
  void holders(const Items& items, std::vector<uint32_t>& holder, std::vector<size_t>& count) const;
  uint32_t index_of(const std::string& worker);

  std::vector<uint32_t> holder_;  // per item id: 1 + index into workers_; 0: none
  std::vector<uint64_t> fingerprint_;
  std::vector<std::string> workers_;
};

}  // namespace parapm::service
