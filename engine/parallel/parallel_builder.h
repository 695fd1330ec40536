// The parallel build's steps (build_progressive_mesh_parallel, parallel_build.h, is their
// plan): the set-up, the rounds, the final pass and the PM. Internal to the engine.
//
// A round: plan it (how many subsets, what goal), partition the live mesh (or take the
// partition drawn ahead), bound the goal by the border band, extract one job per subset with
// the master's state and keys, run the jobs, merge their records and states into the whole
// mesh and the master, then the band pass along the borders of two rounds. Work that does not
// change what the master step at hand reads runs beside it (the next partition, the append of
// the last round's records), and the critical path counts only what outlasts it.
//
// Not thread-safe: one builder per build, driven by one thread (it runs its pool itself).
#pragma once

#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <vector>

#include "parallel/collapse_merge.h"
#include "parallel/edge_keys.h"
#include "parallel/live_pass.h"
#include "parallel/parallel_build.h"
#include "simplify/collapse_mesh.h"
#include "simplify/copy_groups.h"
#include "util/thread_team.h"

namespace parapm {

class ParallelBuilder {
 public:
  // Checks the options (Error(kInvalidInput)); `stats` (null: kept here) is reset.
  ParallelBuilder(const RepairedMesh& repaired, const SimplifyOptions& options,
                  const ParallelOptions& requested, ParallelStats* stats,
                  const ProgressCallback& progress, const CancelToken* cancel, SubsetRunner* runner,
                  const ParallelEvents& events);
  ParallelBuilder(const ParallelBuilder&) = delete;
  ParallelBuilder& operator=(const ParallelBuilder&) = delete;

  // The whole mesh and the master's metric, initialised on it beside the first partition.
  void set_up();
  // One round, if the plan has one; false when the rounds are over.
  bool round();
  // The borders and whatever remains down to the target, sequentially.
  void final_pass();
  // The PM of every collapse, in order; the stats completed.
  ProgressiveMesh progressive_mesh();

 private:
  // What a round does, from the mesh's live faces and vertices, the scheduled rounds left and
  // the last round's figures: whether there is one, with how many subsets, whether it is
  // scheduled, its goal.
  struct RoundPlan {
    bool go = false;
    uint32_t subsets = 0;
    bool scheduled = false;
    uint64_t goal = 0;
  };
  RoundPlan plan_round(uint64_t faces, size_t vertices, uint32_t scheduled_rounds_left,
                       const RoundStats* last) const;
  // Whether a scheduled round counts against the rounds: unless its border band shortened it
  // and it did half of what it was asked.
  static bool counts(const RoundStats& r);

  // A round at work: its figures, its partition, its jobs and what came back.
  struct Round {
    RoundStats rs;
    uint32_t subsets = 0;
    bool scheduled = false;
    std::vector<uint32_t> vertex_subset;
    std::vector<uint8_t> bound;  // its partition's bound vertices
    std::vector<SubsetJob> jobs;
    std::vector<SubsetResult> results;
    std::vector<std::vector<CollapseRecord>> lists;  // the jobs' records
    double ceiling = 0;               // its water level: 95% of its collapses cost less
    bool append_beside_jobs = false;  // the last round's records go into the PM's beside its jobs
    ReplayReport replay;
  };
  struct LiveGraph;
  void draw_round_one(std::shared_ptr<const LiveGraph> source, uint32_t subsets, double start);
  void take_round_one();
  void partition(Round& r);
  void bound_goal_by_border(Round& r);
  void extract_jobs(Round& r);
  void run_subsets(Round& r);
  void merge(Round& r);
  // The jobs' states into the master, the round's water level, the keys and deferred edges
  // they return; beside the replay of their records. Returns its seconds on the critical path.
  double take_results(Round& r);
  void band_pass(Round& r);
  void finish_round(Round& r);
  // A partition foreseen but not taken: the critical path counts what of the append beside the
  // band pass outlasted it.
  void forgo_foreseen();
  void append_pending();
  // `list`'s records after those in records_, in its order, the list kept (keep_list).
  void append_list(std::vector<CollapseRecord> list);
  // Into record_lists_, the pages of its unused capacity released.
  void keep_list(std::vector<CollapseRecord> list);
  // What the team's loops so far took beyond their time with a core per chunk (seconds): the
  // critical path counts the latter.
  double team_saving() const { return team_ ? team_->saved_seconds() : 0; }
  std::shared_ptr<const std::vector<uint32_t>> whole_components();

  // The build's inputs.
  const RepairedMesh& repaired_;
  const Mesh& mesh_;
  const SimplifyOptions& options_;
  const ParallelOptions& requested_;
  ParallelStats local_stats_;
  ParallelStats& st_;
  const ProgressCallback& progress_;
  const CancelToken* cancel_;
  ThreadPoolRunner pool_;
  // The master's passes over the whole mesh while no job runs, in p chunks on the pool's
  // threads: the partitions' live copies and graphs (round 0's beside the set-up, a round's
  // beside the band pass before it, or alone; round 1's walk, on round 0's graph beside round
  // 0, runs on one thread of its own), each round's owned vertices, the band pass's lagging
  // vertices and the PM's assembly.
  ChunkedLoops master_loops_;
  // The band passes' and the final pass's collapses that split into independent pieces (the
  // energy's point projections: PriorityModule::use_team), in p chunks on threads that wait
  // between collapses. A costly metric's only.
  std::optional<ThreadTeam> team_;
  SubsetRunner* runner_;
  const ParallelEvents& events_;
  const std::chrono::steady_clock::time_point start_;
  const double master_cpu_start_;

  // Its targets.
  uint32_t rounds_ = 0;  // scheduled
  uint64_t input_faces_ = 0, target_ = 0, handover_ = 0;
  uint64_t defer_line_ = 0;  // above it, edges are costed when they reach the top
  uint64_t free_line_ = 0;   // above it, the quadric places freely (free_placement_line)
  std::vector<uint8_t> locked_;
  std::vector<uint8_t> on_membrane_;  // membrane_vertices: free to vanish in the final pass
  CopyGroups
      copy_groups_;  // (copy_groups.h) joined by seam collapses in the jobs and the final pass
  // Extra rounds past the handover keep the scheduled rounds' ratio per round, or three
  // rounds' if that is gentler.
  double step_ = 1;

  // The whole mesh and the master's metric, initialised once on the whole mesh (so that the
  // sample points are the sequential build's); every round's jobs take their part of its
  // state and give back what they own, so that the final pass continues from the state a
  // sequential run would have after the same collapses.
  std::optional<CollapseMesh> whole_;
  std::unique_ptr<PriorityModule> master_;
  ParallelOptions parallel_;  // requested_, with the metric's subset floor
  // The master's queue keys: the water level's sample, the jobs' keys after a round, the band
  // pass's; carried into the next round's jobs and the final pass (edge_keys.h).
  std::optional<KeyMemo> keys_;
  // Keys are worth carrying only where a costing costs more than remembering it (costly()).
  bool carry_keys_ = false, carry_deferred_ = false;
  // What the band passes and the final pass cost with: the memo with carried keys, else the
  // master (the memo would answer nothing, and its lookups only cost time).
  PriorityModule* master_queue_ = nullptr;
  SubsetOptions subset_options_;
  bool first_round_ = false;  // round 0's partition is drawn during the set-up
  std::vector<uint32_t> first_partition_;
  double first_partition_seconds_ = 0;
  // The whole mesh's build and the master's initialisation, beside which round 0's partition
  // is drawn, at their critical path.
  double partition_beside_seconds_ = 0;

  uint64_t job_costings_ = 0, sample_costings_ = 0;  // (ParallelStats::costings)
  uint64_t master_sample_costings_ = 0;  // of those, the master's own (sample_on_master)
  uint64_t final_costings_ = 0;          // the final pass's on a live copy (live_pass.h)
  // The quadric's final pass on a copy of the live mesh: whole_ stays as the rounds left it,
  // the PM's base is the copy's.
  std::optional<LivePass> live_;
  // The edges jobs left deferred (global ids, sorted), kept until a collapse changes an end:
  // the next round's jobs and the final pass queue them deferred (SubsetJob::deferred).
  std::vector<DeferredEdge> deferred_;
  // The whole mesh's connected components, found once (beside round 0's jobs, else at the first
  // band pass or the final pass), for the size rule of each one after it (collapses neither
  // merge nor split them).
  std::shared_ptr<const std::vector<uint32_t>> components_;

  // Every collapse so far, in the PM's order, as its record's address in record_lists_ (a
  // record never moves: the PM's assembly reads it there). At most one per vertex: reserved
  // once.
  std::vector<const CollapseRecord*> records_;
  // The lists the records lie in: the subsets', the band passes', the final pass's (moved in
  // whole, their items staying where they are).
  std::vector<std::vector<CollapseRecord>> record_lists_;
  // A round's subsets' lists wait for the next step of the master to go into records_, k-way
  // merged by cost (the band pass's records follow them). Nothing reads records_ before the PM
  // is assembled, so the merge by cost runs beside the band pass, the next round's partition,
  // or the final pass, off the critical path.
  std::vector<std::vector<CollapseRecord>> pending_lists_;
  std::vector<uint8_t> bound_before_;  // the previous round's bound vertices (subset_rule.h)
  std::vector<uint8_t> early_bound_;   // round 1's, found while checking its early partition
  std::vector<uint32_t> face_subset_;  // the round's: per face, the job owning its corners
  double subsets_cpu_ = 0;             // CPU spent off the master's thread
  uint32_t round_index_ = 0;
  // Scheduled rounds still to come: geometric steps to the handover; a round shortened by its
  // border band does not count, unless its jobs did not do half of it.
  uint32_t scheduled_left_ = 0;
  // The next round's partition, drawn ahead: beside round 0 (round 1's), or beside the
  // band pass on a copy of the mesh before it (the band pass moves a few hundred vertices
  // along old borders). Used if the round has as many subsets as foreseen.
  struct Foreseen {
    bool beside_band = false;  // the last round's lists were appended beside its band pass
    bool drawn = false;        // and the next round's partition drawn
    uint32_t subsets = 0;
    std::vector<uint32_t> vertex_subset;
    double copy_seconds = 0, partition_seconds = 0, append_seconds = 0, band_seconds = 0;
    double beside_seconds = 0;  // round 1's: the critical path's seconds it ran beside
  } foreseen_;
  // Round 1's partition, drawn from the set-up on (draw_round_one), and where it started on the
  // critical path's clock: after the set-up's loops before round 0's partition and that
  // partition.
  struct DrawnAhead {
    std::vector<uint32_t> vertex_subset;
    double seconds = 0, cpu_seconds = 0;
  };
  std::future<DrawnAhead> round_one_;
  bool round_one_elsewhere_ = false;  // on a thread of its own
  uint32_t round_one_subsets_ = 0;
  double round_one_start_ = 0;
};

}  // namespace parapm
