// The non-conflict rule (engine/parallel/subset_rule.h), proved on real meshes: the subsets'
// collapse sequences, run each on its own job, replay on the whole mesh in any interleaving
// that keeps each subset's order, every collapse finding the faces and apexes its subset saw,
// and every interleaving ends in the same mesh.
#include <gtest/gtest.h>

#include <algorithm>

#include "parallel/collapse_merge.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "parallel/subset_rule.h"
#include "parallel_test_support.h"
#include "partition/partition.h"
#include "simplify/modules.h"
#include "simplify/simplify.h"
#include "util/error.h"

namespace parapm {
namespace {

struct Round {
  RepairedMesh repaired;
  Partition partition;
  std::vector<SubsetJob> jobs;
  std::vector<SubsetResult> results;
};

Round run_round(const std::string& name, const std::string& metric, uint32_t p) {
  Round round;
  round.repaired = testing::repaired_test_mesh(name);
  const Mesh& mesh = round.repaired.mesh;
  round.partition = partition_mesh(mesh, p);
  SubsetOptions options;
  options.metric = metric;
  // One point per vertex: a job's energy then samples its subset as the whole mesh's does
  // (expect_interleavings_commute replays the jobs' records on the whole mesh).
  options.samples_per_face = 0;
  options.reference_diagonal = bounding_box(mesh).diagonal();
  const CollapseMesh whole(mesh);
  round.jobs = extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float,
                               locked_vertices(round.repaired), round.partition.vertex_subset, p, 0,
                               options);
  for (const SubsetJob& job : round.jobs) round.results.push_back(simplify_subset(job));
  return round;
}

std::vector<std::vector<CollapseRecord>> lists_of(const Round& round) {
  std::vector<std::vector<CollapseRecord>> lists;
  for (const SubsetResult& r : round.results) lists.push_back(r.records);
  return lists;
}

// Live faces of a CollapseMesh, for comparing end states.
std::vector<std::pair<FaceId, Triangle>> live_faces(const CollapseMesh& mesh) {
  std::vector<std::pair<FaceId, Triangle>> faces;
  for (FaceId f = 0; f < mesh.face_capacity(); ++f)
    if (mesh.face_alive(f)) faces.emplace_back(f, mesh.face(f));
  return faces;
}

// The live vertices of each subset, in id order, in chunks side by side as in one pass, some of
// them dead after a round of collapses; a subset out of range is named, chunked or not.
TEST(SubsetRule, OwnedVerticesInChunksAreTheOnePassLists) {
  Round round = run_round("stratocaster-9k.ply", "quadric", 8);
  CollapseMesh whole(round.repaired.mesh);
  std::vector<CollapseRecord> merged = merge_by_cost(lists_of(round));
  replay_collapses(whole, merged, nullptr);
  ASSERT_LT(whole.live_vertices(), whole.vertex_capacity());
  const std::vector<uint32_t>& subsets = round.partition.vertex_subset;
  const auto one_pass = owned_vertices(whole, subsets, 8);
  size_t listed = 0;
  for (const auto& list : one_pass) {
    EXPECT_TRUE(std::is_sorted(list.begin(), list.end()));
    listed += list.size();
  }
  EXPECT_EQ(listed, whole.live_vertices());
  ChunkedLoops loops(5, 2, 16);
  EXPECT_EQ(owned_vertices(whole, subsets, 8, loops), one_pass);
  std::vector<uint32_t> bad = subsets;
  VertexId live = 0;
  while (!whole.vertex_alive(live)) ++live;
  bad[live] = 8;
  EXPECT_THROW(owned_vertices(whole, bad, 8, loops), Error);
  EXPECT_THROW(owned_vertices(whole, bad, 8), Error);
}

TEST(SubsetRule, JobsHoldTheirSubsetAndAOneRingHaloOnly) {
  const Round round = run_round("cad-cycloidal-43k.ply", "quadric", 4);
  const Mesh& mesh = round.repaired.mesh;
  size_t job_faces = 0, owned_faces = 0;
  std::vector<uint32_t> whole_valence(mesh.vertex_count(), 0);
  for (const Triangle& t : mesh.faces)
    for (VertexId v : t) ++whole_valence[v];
  for (const SubsetJob& job : round.jobs) {
    validate_subset_job(job);
    job_faces += job.mesh.face_count();
    owned_faces += job.owned_faces;
    EXPECT_LT(job.mesh.face_count(), mesh.face_count() / 2) << "subset " << job.subset;
    // Every face around an owned vertex is in the job: same valence as in the whole mesh.
    std::vector<uint32_t> valence(job.mesh.vertex_count(), 0);
    for (const Triangle& t : job.mesh.faces)
      for (VertexId v : t) ++valence[v];
    for (VertexId v = 0; v < job.mesh.vertex_count(); ++v) {
      if (job.owned[v]) {
        ASSERT_EQ(valence[v], whole_valence[job.global_vertex[v]]) << "owned vertex " << v;
      } else {
        ASSERT_LE(valence[v], whole_valence[job.global_vertex[v]]) << "halo vertex " << v;
      }
    }
  }
  // Faces with three owned vertices are counted once; halos add a band along the cuts.
  EXPECT_LE(owned_faces, mesh.face_count());
  EXPECT_LT(job_faces, mesh.face_count() * 12 / 10) << "the halos are a thin band";
}

TEST(SubsetRule, EveryCollapseHasItsWholeStarInItsSubset) {
  const Round round = run_round("stratocaster-9k.ply", "quadric", 4);
  for (const SubsetResult& result : round.results) {
    ASSERT_GT(result.records.size(), 100u);
    CollapseMesh whole(round.repaired.mesh);
    // Replaying one subset alone: before each collapse, the star of (vs, vt) on the whole mesh
    // has only vertices of that subset.
    for (const CollapseRecord& r : result.records) {
      for (VertexId end : {r.vs, r.vt})
        for (FaceId f : whole.faces_of(end))
          for (VertexId n : whole.face(f))
            ASSERT_EQ(round.partition.vertex_subset[n], result.subset)
                << "collapse (" << r.vs << ", " << r.vt << ") reads vertex " << n;
      whole.collapse(r.vs, r.vt, r.position, whole.edge_faces(r.vs, r.vt));
    }
  }
}

// The faces a job can remove (the shares count them): every face its collapses remove is one,
// run with no target, on a real mesh; and the border it cannot touch is not empty.
TEST(SubsetRule, JobsRemoveOnlyTheirRemovableFaces) {
  const Round round = run_round("stratocaster-9k.ply", "quadric", 4);
  for (size_t s = 0; s < round.jobs.size(); ++s) {
    const SubsetJob& job = round.jobs[s];
    const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
    const uint64_t removable = removable_faces(job.mesh, free);
    EXPECT_LT(removable, job.owned_faces) << "subset " << s;
    std::vector<uint8_t> can_go(job.mesh.face_count(), 0);
    for (FaceId f = 0; f < job.mesh.face_count(); ++f) {
      const Triangle& t = job.mesh.faces[f];
      can_go[f] = free[t[0]] + free[t[1]] + free[t[2]] >= 2;
    }
    size_t removed = 0;
    for (const CollapseRecord& r : round.results[s].records)
      for (FaceId global : {r.fl, r.fr}) {
        if (global == kNoId) continue;
        const auto it = std::lower_bound(job.global_face.begin(), job.global_face.end(), global);
        ASSERT_TRUE(it != job.global_face.end() && *it == global);
        EXPECT_TRUE(can_go[it - job.global_face.begin()]) << "subset " << s << " face " << global;
        ++removed;
      }
    EXPECT_GT(removed, removable / 2) << "subset " << s;
    EXPECT_LE(removed, removable) << "subset " << s;
  }
}

// The border the round's bound counts without extracting the jobs (border_faces over
// bound_vertices) is exactly what the jobs cannot remove: with their removable faces it makes
// every live face of the mesh, on a real mesh cut in 2 and 8; found in chunks, the same.
TEST(SubsetRule, BorderFacesAreWhatNoJobCanRemove) {
  for (uint32_t p : {2u, 8u}) {
    const RepairedMesh repaired = testing::repaired_test_mesh("gmsh-aneurysm-20k.stl.gz");
    const Mesh& mesh = repaired.mesh;
    const Partition partition = partition_mesh(mesh, p);
    const CollapseMesh whole(mesh);
    SubsetOptions options;
    options.metric = "quadric";
    const std::vector<SubsetJob> jobs =
        extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float,
                        locked_vertices(repaired), partition.vertex_subset, p, 0, options);
    uint64_t removable = 0;
    for (const SubsetJob& job : jobs)
      removable += removable_faces(job.mesh, free_vertices(job.mesh, job.owned));
    const std::vector<uint8_t> bound = bound_vertices(whole, partition.vertex_subset);
    const uint64_t border = border_faces(whole, bound);
    EXPECT_GT(border, 0u) << "p = " << p;
    EXPECT_EQ(border + removable, whole.live_faces()) << "p = " << p;
    // In chunks on threads, the same flags and count.
    ChunkedLoops loops(7, 3);
    EXPECT_EQ(bound_vertices(whole, partition.vertex_subset, &loops), bound) << "p = " << p;
    EXPECT_EQ(border_faces(whole, bound, &loops), border) << "p = " << p;
    for (const SubsetJob& job : jobs) {
      const std::vector<uint8_t> free = free_vertices(job.mesh, job.owned);
      for (VertexId v = 0; v < job.mesh.vertex_count(); ++v) {
        if (job.owned[v]) {
          EXPECT_EQ(bound[job.global_vertex[v]], !free[v]) << "p = " << p;
        }
      }
    }
  }
}

// The theorem: any interleaving that keeps each subset's order replays (replay_collapses
// checks fl, fr, vl, vr of every record against the whole mesh) and ends in the same mesh.
void expect_interleavings_commute(const std::string& name, const std::string& metric, uint32_t p) {
  const Round round = run_round(name, metric, p);
  const Mesh& mesh = round.repaired.mesh;
  std::vector<std::vector<CollapseRecord>> orders;
  orders.push_back(merge_by_cost(lists_of(round)));
  // Subset after subset, last subset first.
  {
    std::vector<CollapseRecord> seq;
    for (size_t s = round.results.size(); s-- > 0;)
      seq.insert(seq.end(), round.results[s].records.begin(), round.results[s].records.end());
    orders.push_back(seq);
  }
  // Round-robin, the 1999 merge.
  {
    std::vector<CollapseRecord> seq;
    for (size_t i = 0;; ++i) {
      bool any = false;
      for (const SubsetResult& r : round.results)
        if (i < r.records.size()) seq.push_back(r.records[i]), any = true;
      if (!any) break;
    }
    orders.push_back(seq);
  }
  std::vector<std::pair<FaceId, Triangle>> first_end;
  std::vector<Vec3> first_positions;
  for (size_t k = 0; k < orders.size(); ++k) {
    CollapseMesh whole(mesh);
    SimplifyOptions options;
    options.metric = metric;
    options.samples_per_face = 0;  // as the jobs' (run_round)
    auto priority = make_priority_module(options, mesh, locked_vertices(round.repaired));
    priority->initialize(whole);
    ReplayReport report;
    ASSERT_NO_THROW(report = replay_collapses(whole, orders[k], priority.get()))
        << name << " order " << k;
    EXPECT_EQ(report.collapses, orders[k].size());
    // One random point per vertex only: the whole mesh's metric state follows each subset's
    // exactly, down to the attribute values E_scalar computes.
    EXPECT_EQ(report.attribute_mismatches, 0u) << name << " order " << k;
    if (k == 0) {
      first_end = live_faces(whole);
      first_positions = whole.positions();
    } else {
      EXPECT_EQ(live_faces(whole), first_end) << name << " order " << k;
      EXPECT_EQ(whole.positions(), first_positions) << name << " order " << k;
    }
  }
}

TEST(SubsetRule, InterleavingsReplayAndCommuteQuadric) {
  expect_interleavings_commute("stratocaster-9k.ply", "quadric", 4);
  expect_interleavings_commute("cad-cycloidal-43k.ply", "quadric", 3);
}

TEST(SubsetRule, InterleavingsReplayAndCommuteEnergy) {
  expect_interleavings_commute("pymeshlab-colored-airplane-11k.ply", "energy", 3);
  expect_interleavings_commute("stratocaster-9k.ply", "energy", 2);
}

// The subsets replayed side by side (replay_subsets) end in the mesh a merged replay leaves,
// down to every vertex's face list in its order, whatever the thread count; real meshes, both
// metrics.
void expect_side_by_side_replay_is_the_merged_one(const std::string& name,
                                                  const std::string& metric, uint32_t p) {
  const Round round = run_round(name, metric, p);
  CollapseMesh merged(round.repaired.mesh);
  std::vector<CollapseRecord> sequence = merge_by_cost(lists_of(round));
  replay_collapses(merged, sequence, nullptr);
  for (unsigned threads : {1u, 2u, 4u}) {
    CollapseMesh side(round.repaired.mesh);
    bool ran_beside = false;
    std::vector<std::vector<CollapseRecord>> lists = lists_of(round);
    const ReplayReport report = replay_subsets(side, lists, round.partition.vertex_subset, threads,
                                               [&] { ran_beside = true; });
    EXPECT_TRUE(ran_beside);
    size_t records = 0;
    for (const SubsetResult& r : round.results) records += r.records.size();
    EXPECT_EQ(report.collapses, records);
    EXPECT_EQ(side.live_faces(), merged.live_faces()) << name << " threads " << threads;
    EXPECT_EQ(side.live_vertices(), merged.live_vertices()) << name << " threads " << threads;
    EXPECT_EQ(live_faces(side), live_faces(merged)) << name << " threads " << threads;
    EXPECT_EQ(side.positions(), merged.positions()) << name << " threads " << threads;
    for (VertexId v = 0; v < side.vertex_capacity(); ++v) {
      ASSERT_TRUE(std::ranges::equal(side.faces_of(v), merged.faces_of(v)))
          << name << " vertex " << v;
      ASSERT_EQ(side.is_boundary(v), merged.is_boundary(v)) << name << " vertex " << v;
    }
  }
}

TEST(SubsetRule, SideBySideReplayIsTheMergedReplay) {
  expect_side_by_side_replay_is_the_merged_one("cad-cycloidal-43k.ply", "quadric", 4);
  expect_side_by_side_replay_is_the_merged_one("pymeshlab-colored-airplane-11k.ply", "energy", 3);
}

// A record that breaks the rule (here: subset 0 names an edge of subset 1, which subset 1's
// own thread may be changing) is refused before the mesh is read around it.
TEST(SubsetRule, SideBySideReplayRefusesARecordOfAnotherSubset) {
  const Round round = run_round("stratocaster-9k.ply", "quadric", 2);
  std::vector<std::vector<CollapseRecord>> lists = lists_of(round);
  ASSERT_FALSE(lists[1].empty());
  lists[0].insert(lists[0].begin(), lists[1].front());
  CollapseMesh whole(round.repaired.mesh);
  try {
    replay_subsets(whole, lists, round.partition.vertex_subset, 2);
    ADD_FAILURE() << "a record of subset 1 replayed as subset 0's";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    EXPECT_NE(std::string(e.what()).find("does not own"), std::string::npos) << e.what();
  }
  // And an edge of subset 0 next to subset 1 (its border), which the jobs never collapse.
  const Mesh& mesh = round.repaired.mesh;
  const std::vector<uint32_t>& subset = round.partition.vertex_subset;
  CollapseRecord border;
  bool found = false;
  for (FaceId f = 0; f < mesh.face_count() && !found; ++f) {
    const Triangle& t = mesh.faces[f];
    for (int k = 0; k < 3 && !found; ++k) {
      const VertexId a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3];
      if (subset[a] == 0 && subset[b] == 0 && subset[c] == 1) {
        CollapseMesh fresh(mesh);
        const EdgeFaces edge = fresh.edge_faces(a, b);
        border.vs = a;
        border.vt = b;
        border.fl = edge.left;
        border.fr = edge.right;
        border.vl = edge.left_apex;
        border.vr = edge.right_apex;
        border.position = mesh.positions[a];
        found = true;
      }
    }
  }
  ASSERT_TRUE(found);
  CollapseMesh again(mesh);
  try {
    std::vector<std::vector<CollapseRecord>> lists = {{border}, {}};
    replay_subsets(again, lists, subset, 2);
    ADD_FAILURE() << "a border edge replayed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("subset rule"), std::string::npos) << e.what();
  }
}

TEST(SubsetRule, ABrokenOrderIsCaughtByTheReplay) {
  const Round round = run_round("stratocaster-9k.ply", "quadric", 2);
  std::vector<CollapseRecord> records = round.results[0].records;
  ASSERT_GT(records.size(), 10u);
  // Swap a collapse with a later one that uses its surviving vertex: the replay must notice.
  size_t later = 0;
  for (size_t i = 1; i < records.size() && later == 0; ++i)
    if (records[i].vs == records[0].vs || records[i].vt == records[0].vs) later = i;
  ASSERT_NE(later, 0u);
  std::swap(records[0], records[later]);
  CollapseMesh whole(round.repaired.mesh);
  EXPECT_THROW(replay_collapses(whole, records, nullptr), Error);
}

// A record of `cost` told apart by its vs.
CollapseRecord record(double cost, VertexId tag) {
  CollapseRecord r;
  r.cost = cost;
  r.vs = tag;
  return r;
}

TEST(SubsetRule, MergeByCostKeepsEachListsOrderAndPrefersCheapHeads) {
  std::vector<std::vector<CollapseRecord>> lists = {
      {record(1, 0), record(5, 1), record(2, 2)}, {record(1, 10), record(3, 11)}, {}};
  const auto merged = merge_by_cost(lists);
  std::vector<VertexId> tags;
  for (const auto& r : merged) tags.push_back(r.vs);
  // Ties go to the lower list; list 0's 2 waits behind its 5, as its order demands.
  EXPECT_EQ(tags, (std::vector<VertexId>{0, 10, 11, 1, 2}));
}

// The merge as addresses (the parallel build's PM order): the same order, after what `out`
// held, each address the record's own place in its list.
TEST(SubsetRule, MergeOrderIsTheMergeAsTheRecordsAddresses) {
  const std::vector<std::vector<CollapseRecord>> lists = {
      {record(1, 0), record(5, 1), record(2, 2)}, {record(1, 10), record(3, 11)}, {}};
  const CollapseRecord before = record(0, 99);
  std::vector<const CollapseRecord*> order{&before};
  append_merge_order(lists, order);
  const std::vector<CollapseRecord> merged = merge_by_cost(lists);
  ASSERT_EQ(order.size(), merged.size() + 1);
  EXPECT_EQ(order[0], &before);
  for (size_t i = 0; i < merged.size(); ++i) EXPECT_EQ(order[i + 1]->vs, merged[i].vs);
  EXPECT_EQ(order[1], &lists[0][0]);
  EXPECT_EQ(order[2], &lists[1][0]);
  EXPECT_EQ(order[5], &lists[0][2]);
}

}  // namespace
}  // namespace parapm
