// The coordinator's registry of workers, as its dispatcher uses it: a slot on the least
// loaded live worker or on a named one, one call more per slot only when queueing ahead, none
// on a suspected worker, and the live slots counted.
#include <gtest/gtest.h>

#include <map>
#include <thread>

#include "worker_registry.h"

namespace parapm::service {
namespace {

using std::chrono::milliseconds;

// Each worker at an address of its own (one registering at a known address replaces it).
WorkerDescription worker(const std::string& name, uint32_t threads, double capacity = 1) {
  static int port = 40000;
  WorkerDescription w;
  w.address = "127.0.0.1:" + std::to_string(++port);
  w.name = name;
  w.threads = threads;
  w.capacity = capacity;
  return w;
}

TEST(WorkerRegistry, QueueingAheadTakesOneCallMorePerSlot) {
  WorkerRegistry registry(milliseconds(60000));
  const std::string one = registry.add(worker("one", 1));
  const std::string two = registry.add(worker("two", 2));
  EXPECT_EQ(registry.live_slots(), 3u);

  std::map<std::string, int> calls;
  for (int i = 0; i < 3; ++i) {
    const std::optional<WorkerSlot> slot = registry.acquire();
    ASSERT_TRUE(slot) << "free slot " << i;
    ++calls[slot->worker_id];
  }
  EXPECT_EQ(calls[one], 1);
  EXPECT_EQ(calls[two], 2);
  EXPECT_FALSE(registry.acquire()) << "every slot is busy";

  for (int i = 0; i < 3; ++i) {
    const std::optional<WorkerSlot> slot = registry.acquire({}, true);
    ASSERT_TRUE(slot) << "queued ahead " << i;
    ++calls[slot->worker_id];
  }
  EXPECT_EQ(calls[one], 2);
  EXPECT_EQ(calls[two], 4);
  EXPECT_FALSE(registry.acquire({}, true)) << "one call queued ahead per slot at most";

  // A call that ends frees room for one more, queued ahead or not.
  registry.release(one);
  EXPECT_FALSE(registry.acquire()) << "worker one still runs a call in its one slot";
  const std::optional<WorkerSlot> again = registry.acquire({two}, true);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->worker_id, one);
}

// A slot on one named worker (the holder of a job's quadrics), under the same bounds.
TEST(WorkerRegistry, ASlotOnANamedWorker) {
  WorkerRegistry registry(milliseconds(60000));
  const std::string one = registry.add(worker("one", 1));
  const std::string two = registry.add(worker("two", 1));
  ASSERT_TRUE(registry.acquire_on(two));
  EXPECT_FALSE(registry.acquire_on(two)) << "its one slot is busy";
  ASSERT_TRUE(registry.acquire_on(two, true)) << "one call queued ahead";
  EXPECT_FALSE(registry.acquire_on(two, true));
  EXPECT_FALSE(registry.acquire_on("worker-unknown"));
  EXPECT_EQ(registry.live_slots_by_worker(),
            (std::map<std::string, uint32_t>{{one, 1u}, {two, 1u}}));
  registry.suspect(one);
  EXPECT_FALSE(registry.acquire_on(one)) << "a suspect takes nothing";
  EXPECT_EQ(registry.live_slots_by_worker(), (std::map<std::string, uint32_t>{{two, 1u}}));
  registry.release(two);
  EXPECT_TRUE(registry.acquire_on(two, true));
}

TEST(WorkerRegistry, AQueuedCallGoesToTheLeastLoadedAndNeverToASuspect) {
  WorkerRegistry registry(milliseconds(60000));
  const std::string slow = registry.add(worker("slow", 1, 1));
  const std::string fast = registry.add(worker("fast", 1, 4));
  ASSERT_TRUE(registry.acquire());
  ASSERT_TRUE(registry.acquire());
  // Both busy: the faster worker's queue is the shorter wait.
  const std::optional<WorkerSlot> queued = registry.acquire({}, true);
  ASSERT_TRUE(queued);
  EXPECT_EQ(queued->worker_id, fast);

  registry.suspect(slow);
  EXPECT_FALSE(registry.acquire({}, true)) << "the fast one is full, the slow one suspected";
  EXPECT_TRUE(registry.beat(slow, 1));
  const std::optional<WorkerSlot> after_beat = registry.acquire({}, true);
  ASSERT_TRUE(after_beat);
  EXPECT_EQ(after_beat->worker_id, slow);
}

TEST(WorkerRegistry, DeadWorkersHaveNoSlots) {
  WorkerRegistry registry(milliseconds(1), 1);
  registry.add(worker("gone", 4));
  std::this_thread::sleep_for(milliseconds(20));
  EXPECT_EQ(registry.live_slots(), 0u);
  EXPECT_FALSE(registry.acquire({}, true));
}

}  // namespace
}  // namespace parapm::service
