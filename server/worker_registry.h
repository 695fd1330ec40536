// The workers the coordinator knows: registered over Coordination, alive while they beat,
// each with `threads` slots. The scheduler takes a slot on the least loaded live worker
// (load = busy slots / capacity), so faster workers get more subsets. No gRPC types: the
// registry is plain bookkeeping, shared by the Coordination bridge and the subset dispatcher.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace parapm::service {

struct WorkerDescription {
  std::string address;  // where its WorkerService listens
  std::string name;
  uint32_t threads = 1;
  double capacity = 1;
};

struct WorkerSlot {
  std::string worker_id;
  std::string address;
  std::string name;
};

class WorkerRegistry {
 public:
  // A worker missing this long is dead (its subsets are dispatched again).
  explicit WorkerRegistry(std::chrono::milliseconds heartbeat,
                          unsigned missed_beats_until_dead = 3);

  std::chrono::milliseconds heartbeat() const { return heartbeat_; }

  // A new id every time; a worker registering again from the same address replaces its old
  // entry (it restarted: whatever ran there is gone).
  std::string add(const WorkerDescription& worker);
  // False for an unknown (or dead and forgotten) id: the worker must register again.
  bool beat(const std::string& worker_id, uint32_t running_subsets);
  bool alive(const std::string& worker_id);
  size_t live_count();
  // The live workers' ids and slots (not suspected ones).
  std::map<std::string, uint32_t> live_slots_by_worker();

  // A slot on the least loaded live worker not in `avoid`, if any has a free one. With
  // `queue_ahead`, a worker whose slots are all busy takes up to one call more per slot: the
  // call waits at the worker, its job already sent and decoded, and starts the moment a slot
  // frees there.
  std::optional<WorkerSlot> acquire(const std::set<std::string>& avoid = {},
                                    bool queue_ahead = false);
  // A slot on that worker, if it is live, not suspected, and has a free one (with
  // `queue_ahead`, as acquire()).
  std::optional<WorkerSlot> acquire_on(const std::string& worker_id, bool queue_ahead = false);
  // The slots of the live workers, summed.
  size_t live_slots();
  void release(const std::string& worker_id);
  // Called after a call to it failed for a reason of its own (unreachable): it takes no more
  // subsets until it beats again.
  void suspect(const std::string& worker_id);

 private:
  struct Entry {
    WorkerDescription description;
    std::chrono::steady_clock::time_point last_beat;
    uint32_t busy = 0;  // calls it holds, running or queued ahead
    bool suspected = false;
  };
  // Forgets workers that missed their beats. Caller holds mutex_.
  void expire();

  std::chrono::milliseconds heartbeat_;
  unsigned missed_beats_;
  std::mutex mutex_;
  std::map<std::string, Entry> workers_;
};

}  // namespace parapm::service
