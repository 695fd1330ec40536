// Job events: seq starts at 1 and increases per job, after_seq filters, concurrent appends
// from many threads never share or skip a seq, and an event for a missing job is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "storage/job_store.h"
#include "storage_test_util.h"

namespace parapm::service {
namespace {

using testing::expect_error;
using testing::TempDir;

class JobEventsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    MeshRecord mesh;
    mesh.mesh_id = "mesh-1";
    mesh.sha256 = std::string(64, 'a');
    store_.add_mesh(mesh);
    for (const char* id : {"job-a", "job-b"}) {
      JobRecord job;
      job.job_id = id;
      job.mesh_id = "mesh-1";
      store_.add_job(job);
    }
  }

  TempDir dir_;
  JobStore store_{dir_.path() / "parapm.db"};
};

TEST_F(JobEventsTest, SeqCountsFromOnePerJob) {
  EXPECT_EQ(store_.append_event("job-a", 10, "a1"), 1u);
  EXPECT_EQ(store_.append_event("job-a", 11, "a2"), 2u);
  EXPECT_EQ(store_.append_event("job-b", 12, "b1"), 1u);
  EXPECT_EQ(store_.append_event("job-a", 13, std::string("a3\0bin", 6)), 3u);
  EXPECT_EQ(store_.append_event("job-b", 14, ""), 2u);

  const std::vector<EventRecord> a = store_.events("job-a", 0);
  ASSERT_EQ(a.size(), 3u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].job_id, "job-a");
    EXPECT_EQ(a[i].seq, i + 1);
  }
  EXPECT_EQ(a[0].payload, "a1");
  EXPECT_EQ(a[2].payload, std::string("a3\0bin", 6));
  EXPECT_EQ(a[2].unix_ms, 13);
  const std::vector<EventRecord> b = store_.events("job-b", 0);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].payload, "");
}

TEST_F(JobEventsTest, AfterSeqReturnsOnlyLaterEvents) {
  for (int i = 0; i < 5; ++i)
    store_.append_event("job-a", i, std::string("e").append(std::to_string(i + 1)));
  const std::vector<EventRecord> later = store_.events("job-a", 3);
  ASSERT_EQ(later.size(), 2u);
  EXPECT_EQ(later[0].seq, 4u);
  EXPECT_EQ(later[0].payload, "e4");
  EXPECT_EQ(later[1].seq, 5u);
  EXPECT_TRUE(store_.events("job-a", 5).empty());
  EXPECT_TRUE(store_.events("job-a", UINT64_MAX).empty());
  EXPECT_TRUE(store_.events("job-nope", 0).empty());
}

TEST_F(JobEventsTest, EventForAMissingJobIsNotFound) {
  expect_error([&] { store_.append_event("job-ghost", 1, "x"); }, ErrorCode::kNotFound,
               {"appending an event to job job-ghost", "FOREIGN KEY"});
}

TEST_F(JobEventsTest, ConcurrentAppendsGetDistinctIncreasingSeqs) {
  constexpr int kThreads = 8, kPerThread = 50;
  std::vector<std::vector<uint64_t>> seqs(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t)
    threads.emplace_back([&, t] {
      for (int i = 0; i < kPerThread; ++i)
        seqs[t].push_back(
            store_.append_event("job-a", t, std::to_string(t) + ":" + std::to_string(i)));
    });
  for (std::thread& thread : threads) thread.join();

  std::set<uint64_t> all;
  for (const std::vector<uint64_t>& mine : seqs) {
    EXPECT_TRUE(std::is_sorted(mine.begin(), mine.end())) << "one thread's seqs increase";
    all.insert(mine.begin(), mine.end());
  }
  ASSERT_EQ(all.size(), size_t{kThreads * kPerThread}) << "no seq given twice";
  EXPECT_EQ(*all.begin(), 1u);
  EXPECT_EQ(*all.rbegin(), uint64_t{kThreads * kPerThread}) << "no seq skipped";
  const std::vector<EventRecord> stored = store_.events("job-a", 0);
  ASSERT_EQ(stored.size(), all.size());
  for (size_t i = 0; i < stored.size(); ++i) EXPECT_EQ(stored[i].seq, i + 1);
}

// A job's end (its final status and its terminal event) is one transaction: the event takes
// the next seq, and a reader never sees the status without the event. A watcher that found a
// job done but not its "finished" event used to end its stream without it (seen once in eight
// concurrent service jobs, when the status was written before the event).
TEST_F(JobEventsTest, EndingAJobStoresItsStatusAndLastEventTogether) {
  EXPECT_EQ(store_.append_event("job-a", 10, "started"), 1u);
  JobRecord job = *store_.find_job("job-a");
  job.status = JobStatus::kDone;
  EXPECT_EQ(store_.end_job(job, 11, "finished"), 2u);
  EXPECT_EQ(store_.find_job("job-a")->status, JobStatus::kDone);
  const std::vector<EventRecord> events = store_.events("job-a", 0);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].payload, "finished");
  EXPECT_EQ(events[1].unix_ms, 11);

  JobRecord ghost = job;
  ghost.job_id = "job-ghost";
  expect_error([&] { store_.end_job(ghost, 12, "finished"); }, ErrorCode::kNotFound, {"job-ghost"});
  EXPECT_TRUE(store_.events("job-ghost", 0).empty());

  // Many jobs ended on one thread while another reads each job's status, then its events.
  constexpr int kJobs = 300;
  for (int i = 0; i < kJobs; ++i) {
    JobRecord j;
    j.job_id = "job-" + std::to_string(i);
    j.mesh_id = "mesh-1";
    store_.add_job(j);
  }
  std::atomic<bool> writing{true};
  std::thread writer([&] {
    for (int i = 0; i < kJobs; ++i) {
      JobRecord j = *store_.find_job("job-" + std::to_string(i));
      j.status = JobStatus::kDone;
      store_.end_job(j, 20, "finished");
    }
    writing = false;
  });
  int seen_done = 0, missing = 0;
  while (writing)
    for (int i = 0; i < kJobs; ++i) {
      const std::string id = "job-" + std::to_string(i);
      if (store_.find_job(id)->status != JobStatus::kDone) continue;
      ++seen_done;
      if (store_.events(id, 0).empty()) ++missing;
    }
  writer.join();
  EXPECT_EQ(missing, 0) << "of " << seen_done << " jobs read as done";
}

}  // namespace
}  // namespace parapm::service
