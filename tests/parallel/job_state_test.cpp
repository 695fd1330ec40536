// The metric state that travels with the subset jobs (engine/parallel/job_state.h,
// simplify/module_state.h), on real meshes: export then import gives a module that costs and
// places every edge as the original, and after a round the master's imported state is,
// point for point, the state a replay of every merged record through collapsed() gives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>

#include "drawn_meshes.h"
#include "parallel/collapse_merge.h"
#include "parallel/job_codec.h"
#include "parallel/job_state.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "parallel_test_support.h"
#include "partition/partition.h"
#include "simplify/energy_priority.h"
#include "simplify/quadric_priority.h"
#include "simplify/simplifier.h"
#include "simplify/simplify.h"
#include "util/error.h"

namespace parapm {
namespace {

SimplifyOptions options_of(const std::string& metric) {
  SimplifyOptions options;
  options.metric = metric;
  options.samples_per_face = metric == "energy" ? 1 : 0;  // points on faces from the start
  return options;
}

// One job owning the whole live mesh (p = 1), its module imported from `master`, and every
// edge costed by both, as a queue key and as a collapse to perform: the same end kept, the
// same position and cost. `exact`: bit for bit
// (the job's mesh lists each vertex's faces in id order; after collapses the whole mesh's
// lists are in another order, which changes the order of the energy's sums, hence the last
// bits).
void expect_round_trip(const RepairedMesh& repaired, const SimplifyOptions& options,
                       const CollapseMesh& whole, PriorityModule& master, bool exact,
                       const std::string& what) {
  const Mesh& mesh = repaired.mesh;
  const std::vector<uint32_t> one_subset(whole.vertex_capacity(), 0);
  std::vector<SubsetJob> jobs = extract_subsets(whole, mesh.layout, mesh.wedge_values,
                                                mesh.positions_are_float, locked_vertices(repaired),
                                                one_subset, 1, 0, subset_options_of(options, mesh));
  SubsetJob& job = jobs.at(0);
  job.state = export_job_state(master, job);
  CollapseMesh local(job.mesh);
  std::unique_ptr<PriorityModule> imported =
      make_priority_module(options, job.mesh, job.locked, job.options.reference_diagonal);
  import_job_state(*imported, local, job);
  size_t edges = 0, placed = 0;
  double worst = 0;
  for (VertexId a = 0; a < local.vertex_capacity(); ++a) {
    if (!local.vertex_alive(a)) continue;
    std::vector<VertexId> around;
    local.neighbors(a, around);
    for (VertexId b : around)
      for (const Costing costing : {Costing::kQueue, Costing::kPerform}) {
        if (b < a) continue;
        ++edges;
        CollapseCandidate x, y;
        const bool ok_master =
            master.evaluate(whole, job.global_vertex[a], job.global_vertex[b], x, costing);
        const bool ok_imported = imported->evaluate(local, a, b, y, costing);
        ASSERT_EQ(ok_master, ok_imported) << what << " edge " << a << " " << b;
        if (!ok_master) continue;
        ++placed;
        ASSERT_EQ(x.vs, job.global_vertex[y.vs]) << what;
        ASSERT_EQ(x.vt, job.global_vertex[y.vt]) << what;
        if (exact) {
          ASSERT_EQ(x.cost, y.cost) << what << " edge " << a << " " << b;
          for (int k = 0; k < 3; ++k) ASSERT_EQ(x.position[k], y.position[k]) << what;
          ASSERT_EQ(x.error, y.error) << what;
        } else {
          const double scale = std::max({std::abs(x.cost), 1e-30});
          worst = std::max(worst, std::abs(x.cost - y.cost) / scale);
          ASSERT_NEAR(x.cost, y.cost, 1e-6 * scale + 1e-24) << what << " edge " << a << " " << b;
          for (int k = 0; k < 3; ++k)
            ASSERT_NEAR(x.position[k], y.position[k], 1e-9 * job.options.reference_diagonal)
                << what;
        }
      }
  }
  EXPECT_GT(placed, edges / 2) << what;
  std::printf("%-40s %6zu edges costed alike (%zu placed; worst relative cost gap %.2e)\n",
              what.c_str(), edges, placed, worst);
}

TEST(JobState, ExportThenImportCostsEveryEdgeAlike) {
  for (const char* name : {"pymeshlab-colored-airplane-11k.ply", "stratocaster-9k.ply"})
    for (const char* metric : {"quadric", "energy"}) {
      const RepairedMesh repaired = testing::repaired_test_mesh(name);
      const SimplifyOptions options = options_of(metric);
      const std::vector<uint8_t> locked = locked_vertices(repaired);
      CollapseMesh whole(repaired.mesh);
      std::unique_ptr<PriorityModule> master = make_priority_module(options, repaired.mesh, locked);
      master->initialize(whole);
      expect_round_trip(repaired, options, whole, *master, true,
                        std::string(name) + " " + metric + " input");
      // Half way down: points re-projected, parked samples moved, curves and wedge classes
      // changed, quadrics summed.
      std::unique_ptr<PriorityModule> continued = without_initialize(*master);
      Simplifier simplifier(whole, *continued, standard_constraints(locked));
      SimplifierLimits limits;
      limits.target_faces = whole.live_faces() / 2;
      simplifier.run(limits, {}, nullptr);
      expect_round_trip(repaired, options, whole, *master, std::string(metric) == "quadric",
                        std::string(name) + " " + metric + " at 50%");
    }
}

// Per face of `mesh`, the subset of its three corners when they agree, kNoId otherwise.
std::vector<uint32_t> face_subsets(const CollapseMesh& mesh,
                                   const std::vector<uint32_t>& vertex_subset) {
  std::vector<uint32_t> out(mesh.face_capacity(), kNoId);
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!mesh.face_alive(f)) continue;
    const Triangle& t = mesh.face(f);
    if (vertex_subset[t[0]] == vertex_subset[t[1]] && vertex_subset[t[1]] == vertex_subset[t[2]])
      out[f] = vertex_subset[t[0]];
  }
  return out;
}

// A round of p subsets on `whole` (the master's module `master` initialised on it), as the
// parallel build does it: new partition of the live mesh, jobs with state, merge by cost. The
// records replay on `whole` and on `twin` (the same mesh); `master` follows by importing the
// jobs' returned states, `replayed` by collapsed() on every record.
void round_both_ways(const RepairedMesh& repaired, const SimplifyOptions& options, uint32_t p,
                     uint32_t round, CollapseMesh& whole, PriorityModule& master,
                     CollapseMesh& twin, PriorityModule& replayed, ReplayReport& report) {
  const Mesh& mesh = repaired.mesh;
  Mesh live;  // the live part, compacted, for the partitioner
  std::vector<VertexId> compact(whole.vertex_capacity(), kNoId);
  for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
    if (whole.vertex_alive(v)) {
      compact[v] = VertexId(live.positions.size());
      live.positions.push_back(whole.position(v));
    }
  for (FaceId f = 0; f < whole.face_capacity(); ++f)
    if (whole.face_alive(f)) {
      const Triangle& t = whole.face(f);
      live.faces.push_back({compact[t[0]], compact[t[1]], compact[t[2]]});
    }
  PartitionOptions partition_options;
  partition_options.seed = 1 + round;
  const Partition partition = partition_mesh(live, p, partition_options);
  std::vector<uint32_t> vertex_subset(whole.vertex_capacity(), 0);
  for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
    if (compact[v] != kNoId) vertex_subset[v] = partition.vertex_subset[compact[v]];
  SubsetOptions subset_options = subset_options_of(options, mesh);
  std::vector<SubsetJob> jobs =
      extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float,
                      locked_vertices(repaired), vertex_subset, p, round, subset_options);
  std::vector<std::vector<CollapseRecord>> lists;
  std::vector<SubsetResult> results;
  for (SubsetJob& job : jobs) {
    job.options.target_faces = job.mesh.face_count() * 2 / 5;
    job.state = export_job_state(master, job);
    results.push_back(simplify_subset(job));
    lists.push_back(results.back().records);
  }
  std::vector<CollapseRecord> merged = merge_by_cost(std::move(lists));
  ASSERT_GT(merged.size(), whole.live_faces() / 8);
  // Side by side, as the build takes them (before the replay: the faces' owners are those of
  // the jobs' start).
  std::vector<const MetricState*> states;
  std::vector<const std::vector<CollapseRecord>*> records;
  for (const SubsetResult& r : results) {
    states.push_back(&r.state);
    records.push_back(&r.records);
  }
  import_result_states(master, states, vertex_subset, face_subsets(whole, vertex_subset), 2,
                       records);
  replay_collapses(whole, merged, nullptr);
  report = replay_collapses(twin, merged, &replayed);
}

TEST(JobState, ImportedStateEqualsTheReplayedState) {
  for (const char* name : {"pymeshlab-colored-airplane-11k.ply", "stratocaster-9k.ply"}) {
    const RepairedMesh repaired = testing::repaired_test_mesh(name);
    const std::vector<uint8_t> locked = locked_vertices(repaired);
    for (const char* metric : {"quadric", "energy"}) {
      const SimplifyOptions options = options_of(metric);
      CollapseMesh whole(repaired.mesh), twin(repaired.mesh);
      auto master = make_priority_module(options, repaired.mesh, locked);
      auto replayed = make_priority_module(options, repaired.mesh, locked);
      master->initialize(whole);
      replayed->initialize(twin);
      for (uint32_t round = 0; round < 2; ++round) {
        ReplayReport report;
        round_both_ways(repaired, options, 3, round, whole, *master, twin, *replayed, report);
        if (HasFatalFailure()) return;
        const std::string what =
            std::string(name) + " " + metric + " round " + std::to_string(round);
        // The jobs' points are the master's, so E_scalar's changes are computed as on the
        // whole mesh (in round 0 the jobs' vertices list their faces as the whole mesh does).
        if (round == 0) {
          EXPECT_EQ(report.attribute_mismatches, 0u) << what;
        }
        if (auto* q = dynamic_cast<QuadricPriority*>(master.get())) {
          auto* r = dynamic_cast<QuadricPriority*>(replayed.get());
          size_t compared = 0;
          for (VertexId v = 0; v < whole.vertex_capacity(); ++v) {
            if (!whole.vertex_alive(v)) continue;
            const Quadric &a = q->quadric(v), &b = r->quadric(v);
            ASSERT_TRUE(a.a00 == b.a00 && a.a01 == b.a01 && a.a02 == b.a02 && a.a11 == b.a11 &&
                        a.a12 == b.a12 && a.a22 == b.a22 && a.b0 == b.b0 && a.b1 == b.b1 &&
                        a.b2 == b.b2 && a.c == b.c && a.weight == b.weight)
                << what << " vertex " << v;
            ++compared;
          }
          std::printf("%-44s %6zu quadrics equal\n", what.c_str(), compared);
          continue;
        }
        const auto* e = dynamic_cast<EnergyPriority*>(master.get());
        const auto* r = dynamic_cast<EnergyPriority*>(replayed.get());
        ASSERT_EQ(e->point_count(), r->point_count());
        // Each point held once: a face a job changed but did not return would keep points
        // that moved on (held twice) or lose the ones that came (held nowhere).
        ASSERT_EQ(e->held_point_count(), r->held_point_count()) << what;
        ASSERT_LE(e->held_point_count(), e->point_count()) << what;
        size_t parked = 0, other_face = 0;
        double sum_master = 0, sum_replayed = 0;
        const auto es = e->point_states(), rs = r->point_states();
        for (size_t i = 0; i < es.size(); ++i) {
          ASSERT_EQ(es[i].parked, rs[i].parked) << what << " point " << i;
          if (es[i].parked != kNoId) {
            ++parked;
            continue;
          }
          sum_master += es[i].distance_sq;
          sum_replayed += rs[i].distance_sq;
          if (es[i].face != rs[i].face) {
            ++other_face;
            continue;
          }
          if (round == 0) {
            ASSERT_EQ(es[i].distance_sq, rs[i].distance_sq) << what << " point " << i;
          }
        }
        // Round 0: exactly. From the second round on, a job's mesh lists each vertex's faces
        // in id order, the whole mesh in the order its collapses left: a point equally close
        // to two faces (a vertex's sample, at distance 0 from all its faces) goes to the first
        // one listed, and from then on it is re-projected with that face's star. The
        // difference stays a few points and the energy stays the same.
        if (round == 0) {
          EXPECT_EQ(other_face, 0u) << what;
        }
        EXPECT_LE(other_face, e->point_count() / 100) << what;
        EXPECT_NEAR(sum_master, sum_replayed, 1e-3 * sum_replayed) << what;
        const SharpCurves &ca = e->curves(), &cb = r->curves();
        ASSERT_EQ(ca.sample_count(), cb.sample_count());
        for (size_t i = 0; i < ca.sample_count(); ++i) {
          ASSERT_EQ(ca.sample_edge(i), cb.sample_edge(i)) << what << " curve sample " << i;
          ASSERT_EQ(ca.sample_distance_sq(i), cb.sample_distance_sq(i)) << what;
        }
        for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
          if (whole.vertex_alive(v)) {
            std::vector<VertexId> x = ca.sharp_neighbors(v), y = cb.sharp_neighbors(v);
            std::sort(x.begin(), x.end());
            std::sort(y.begin(), y.end());
            ASSERT_EQ(x, y) << what << " vertex " << v;
          }
        std::printf(
            "%-44s %6zu points (%zu parked, %zu on another face; E_dist %.6g vs %.6g), "
            "%zu curve samples equal; %llu attribute mismatches\n",
            what.c_str(), e->point_count(), parked, other_face, sum_master, sum_replayed,
            ca.sample_count(), (unsigned long long)report.attribute_mismatches);
      }
    }
  }
}

// The energy's master on stratocaster-9k and the jobs of its two halves (by the sign of x),
// each with the master's state and a target of half its faces.
// The options with the stratocaster's creases kept as curves (off by default), so that the
// states carry curve samples and sharp neighbours to check.
SimplifyOptions creases_on(SimplifyOptions options) {
  options.crease_angle_degrees = 60;
  return options;
}

struct TwoHalves {
  TwoHalves()
      : repaired(testing::repaired_test_mesh("stratocaster-9k.ply")),
        locked(locked_vertices(repaired)),
        options(creases_on(options_of("energy"))),
        whole(repaired.mesh),
        master(make_priority_module(options, repaired.mesh, locked)),
        vertex_subset(whole.vertex_capacity(), 0) {
    const Mesh& mesh = repaired.mesh;
    master->initialize(whole);
    for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
      vertex_subset[v] = whole.position(v)[0] < 0 ? 0 : 1;
    jobs = extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float, locked,
                           vertex_subset, 2, 0, subset_options_of(options, mesh));
    for (SubsetJob& job : jobs) {
      job.options.target_faces = job.mesh.face_count() / 2;
      job.state = export_job_state(*master, job);
    }
  }
  RepairedMesh repaired;
  std::vector<uint8_t> locked;
  SimplifyOptions options;
  CollapseMesh whole;
  std::unique_ptr<PriorityModule> master;
  std::vector<uint32_t> vertex_subset;
  std::vector<SubsetJob> jobs;
};

// `import` throws Error(kInvalidInput) naming `what` (or one of its alternatives, separated by
// '|'), and the master's points are as `before`.
void expect_refused_and_unchanged(const std::function<void()>& import, const std::string& what,
                                  const EnergyPriority& energy,
                                  const std::vector<EnergyPriority::PointState>& before) {
  try {
    import();
    ADD_FAILURE() << what << ": accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput) << what;
    const std::string message = e.what();
    bool named = false;
    for (size_t begin = 0; begin <= what.size();) {
      const size_t end = std::min(what.find('|', begin), what.size());
      named = named || message.find(what.substr(begin, end - begin)) != std::string::npos;
      begin = end + 1;
    }
    EXPECT_TRUE(named) << what << ": " << message;
  }
  const auto after = energy.point_states();
  ASSERT_EQ(after.size(), before.size());
  for (size_t i = 0; i < after.size(); ++i) {
    ASSERT_EQ(after[i].face, before[i].face) << what << " point " << i;
    ASSERT_EQ(after[i].parked, before[i].parked) << what << " point " << i;
    ASSERT_EQ(after[i].distance_sq, before[i].distance_sq) << what << " point " << i;
  }
}

// What a job gives back may come from a worker over the network: an energy state that loses
// track of its points (one given twice, one that is another job's, one moved from where it
// was sampled, one put on a face the state does not list) is refused before the master
// changes, and the honest state is then taken as usual.
TEST(JobState, ATamperedEnergyStateIsRefusedAndChangesNothing) {
  TwoHalves halves;
  const std::unique_ptr<PriorityModule>& master = halves.master;
  const CollapseMesh& whole = halves.whole;
  const std::vector<SubsetJob>& jobs = halves.jobs;
  const SubsetResult result = simplify_subset(jobs.at(0));
  const EnergyState& honest = result.state.energy;
  ASSERT_GT(honest.points.size(), 10u);
  const auto* energy = dynamic_cast<EnergyPriority*>(master.get());
  ASSERT_NE(energy, nullptr);
  const auto before = energy->point_states();

  // A point the other job was given, not this one.
  uint32_t foreign = 0;
  bool found = false;
  for (const EnergyState::Point& p : export_job_state(*master, jobs.at(1)).energy.points)
    if (std::none_of(honest.points.begin(), honest.points.end(),
                     [&](const EnergyState::Point& q) { return q.id == p.id; })) {
      foreign = p.id;
      found = true;
      break;
    }
  ASSERT_TRUE(found);
  const FaceId unlisted = [&] {
    for (FaceId f = 0; f < whole.face_capacity(); ++f)
      if (std::find(honest.faces.begin(), honest.faces.end(), f) == honest.faces.end()) return f;
    return kNoId;
  }();
  ASSERT_NE(unlisted, kNoId);

  struct Tamper {
    const char* what;
    std::function<void(EnergyState&)> change;
  };
  const std::vector<Tamper> tampers = {
      {"given twice", [](EnergyState& s) { s.points.push_back(s.points.front()); }},
      {"is not the job's", [&](EnergyState& s) { s.points.front().id = foreign; }},
      {"does not list",
       [&](EnergyState& s) {
         s.points.front().face = unlisted;
         s.points.front().vertex = kNoId;
       }},
      {"out of range", [](EnergyState& s) { s.points.front().id = 0xfffffff0u; }},
  };
  for (const Tamper& tamper : tampers) {
    MetricState state = result.state;
    tamper.change(state.energy);
    expect_refused_and_unchanged([&] { import_result_state(*master, state, result.records); },
                                 tamper.what, *energy, before);
  }
  EXPECT_NO_THROW(import_result_state(*master, result.state, result.records));
}

// A tail round's job writes and imports its state on several cores (ChunkedLoops): the same
// state as one thread writes, and the job given a team (its import and returned state in
// chunks) makes the run one thread makes. Half way down, so that faces hold runs of points;
// with attributes (E_scalar's values travel with the points) and without.
TEST(JobState, AStateInChunksIsTheStateOfOneThread) {
  for (const char* name : {"stratocaster-9k.ply", "pymeshlab-colored-airplane-11k.ply"}) {
    const RepairedMesh repaired = testing::repaired_test_mesh(name);
    const Mesh& mesh = repaired.mesh;
    const SimplifyOptions options = options_of("energy");
    const std::vector<uint8_t> locked = locked_vertices(repaired);
    CollapseMesh whole(mesh);
    std::unique_ptr<PriorityModule> master = make_priority_module(options, mesh, locked);
    master->initialize(whole);
    std::unique_ptr<PriorityModule> continued = without_initialize(*master);
    Simplifier simplifier(whole, *continued, standard_constraints(locked));
    SimplifierLimits limits;
    limits.target_faces = whole.live_faces() / 3;
    simplifier.run(limits, {}, nullptr);
    std::vector<uint32_t> vertex_subset(whole.vertex_capacity(), 0);
    for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
      vertex_subset[v] = whole.position(v)[0] < 0 ? 0 : 1;
    std::vector<SubsetJob> jobs =
        extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float, locked,
                        vertex_subset, 2, 1, subset_options_of(options, mesh));
    for (SubsetJob& job : jobs) {
      const std::string what = std::string(name) + " subset " + std::to_string(job.subset);
      job.options.target_faces = job.mesh.face_count() / 2;
      job.state = export_job_state(*master, job);
      ChunkedLoops chunks(5, 2, 1);
      SubsetJob chunked = job;
      chunked.state = export_job_state(*master, job, &chunks);
      ASSERT_GT(job.state.energy.points.size(), 2 * job.state.energy.faces.size()) << what;
      EXPECT_EQ(encode_subset_job(chunked), encode_subset_job(job)) << what;
      SubsetResult one = simplify_subset(job);
      JobTeam team;
      team.chunks = 4;
      team.threads = 2;
      team.min_items = JobTeam::kDefaultMinItems;
      SubsetResult teamed = simplify_subset(std::move(chunked), {}, nullptr, nullptr, team);
      ASSERT_EQ(teamed.records.size(), one.records.size()) << what;
      ASSERT_FALSE(one.state.empty()) << what;
      for (SubsetResult* r : {&one, &teamed})
        r->wall_seconds = r->cpu_seconds = r->team_saved_seconds = r->team_cpu_seconds = 0;
      EXPECT_EQ(encode_subset_summary(teamed), encode_subset_summary(one)) << what;
      EXPECT_EQ(encode_collapse_records(teamed.records.data(), teamed.records.size()),
                encode_collapse_records(one.records.data(), one.records.size()))
          << what;
    }
  }
}

// A face's points come as one run: a state that lists a face's points apart (the import would
// fill one list from two chunks) is refused, in chunks or not.
TEST(JobState, AStateListingAFacesPointsApartIsRefused) {
  TwoHalves halves;
  SubsetJob job = halves.jobs.at(0);
  std::vector<EnergyState::Point>& points = job.state.energy.points;
  // A point of a later face's run put on the first face, after another face's run: the first
  // face is named by two runs.
  const FaceId first = points.front().face;
  ASSERT_NE(first, kNoId);
  size_t k = 1;
  while (k < points.size() && points[k].face == first) ++k;  // the second run's start
  ++k;
  while (k < points.size() && points[k].face == points[k - 1].face) ++k;  // the third's
  ASSERT_LT(k, points.size());
  ASSERT_NE(points[k].face, kNoId);
  points[k].face = first;
  for (const unsigned chunks : {1u, 4u}) {
    ChunkedLoops loops(chunks, 2, 1);
    CollapseMesh local(job.mesh);
    std::unique_ptr<PriorityModule> module =
        make_priority_module(halves.options, job.mesh, job.locked, job.options.reference_diagonal);
    try {
      import_job_state(*module, local, job, &loops);
      ADD_FAILURE() << chunks << " chunks: imported";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
      EXPECT_NE(std::string(e.what()).find("not listed together"), std::string::npos) << e.what();
    }
  }
}

// A mesh without sharp edges (a closed sphere, no attributes, no crease curves) keeps no
// per-vertex curve lists: its jobs' states carry no curves and go back as usual, and a state
// that brings curves to such a master (from a worker: a collapse never makes a sharp edge) is
// refused before the master changes.
TEST(JobState, AMasterWithoutCurvesRefusesAStateWithCurves) {
  const RepairedMesh repaired = repair_mesh(testing::uv_sphere(24, 48, 0.1));
  const Mesh& mesh = repaired.mesh;
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  const SimplifyOptions options = options_of("energy");
  const CollapseMesh whole(mesh);
  const std::unique_ptr<PriorityModule> master = make_priority_module(options, mesh, locked);
  master->initialize(whole);
  std::vector<uint32_t> vertex_subset(whole.vertex_capacity());
  for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
    vertex_subset[v] = whole.position(v)[0] < 0 ? 0 : 1;
  std::vector<SubsetJob> jobs =
      extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float, locked,
                      vertex_subset, 2, 0, subset_options_of(options, mesh));
  SubsetJob& job = jobs.at(0);
  job.options.target_faces = job.mesh.face_count() / 2;
  job.state = export_job_state(*master, job);
  ASSERT_TRUE(job.state.energy.sharp_neighbors.empty());
  ASSERT_TRUE(job.state.energy.samples.empty());
  const SubsetResult result = simplify_subset(job);
  ASSERT_FALSE(result.records.empty());
  ASSERT_TRUE(result.state.energy.sharp_neighbors.empty());
  const auto* energy = dynamic_cast<EnergyPriority*>(master.get());
  ASSERT_NE(energy, nullptr);
  const auto before = energy->point_states();

  MetricState curved = result.state;
  EnergyState& state = curved.energy;
  ASSERT_GE(state.vertices.size(), 2u);
  state.sharp_neighbors = {state.vertices[1]};
  for (size_t i = 1; i < state.sharp_begin.size(); ++i) state.sharp_begin[i] = 1;
  expect_refused_and_unchanged([&] { import_result_state(*master, curved, result.records); },
                               "sharp curves for a mesh without any", *energy, before);
  EXPECT_NO_THROW(import_result_state(*master, result.state, result.records));
}

// The states of a round go into the master side by side (import_result_states), so each may
// name only its own subset's faces, vertices and points: a state naming another subset's (a
// worker's reply is untrusted; taken side by side, two threads would write the same face) is
// refused before the master changes, as is one that leaves out a face its job's collapses
// removed; the honest states give the master what taking them one after the other gives.
TEST(JobState, StatesSideBySideTakeOnlyTheirOwnSubsets) {
  TwoHalves halves;
  const std::unique_ptr<PriorityModule>& master = halves.master;
  const CollapseMesh& whole = halves.whole;
  const std::vector<uint32_t>& vertex_subset = halves.vertex_subset;
  auto one_by_one = make_priority_module(halves.options, halves.repaired.mesh, halves.locked);
  one_by_one->initialize(whole);
  const std::vector<uint32_t> face_subset = face_subsets(whole, vertex_subset);
  std::vector<MetricState> honest;
  std::vector<std::vector<CollapseRecord>> records;
  for (const SubsetJob& job : halves.jobs) {
    SubsetResult result = simplify_subset(job);
    honest.push_back(std::move(result.state));
    records.push_back(std::move(result.records));
    ASSERT_GT(honest.back().energy.faces.size(), 10u);
  }
  const std::vector<const std::vector<CollapseRecord>*> changes = {&records[0], &records[1]};
  const auto* energy = dynamic_cast<EnergyPriority*>(master.get());
  ASSERT_NE(energy, nullptr);
  const auto before = energy->point_states();
  const FaceId foreign_face = honest[1].energy.faces.front();
  const VertexId foreign_vertex = honest[1].energy.vertices.front();
  const uint32_t foreign_point = honest[1].energy.points.front().id;

  struct Tamper {
    const char* what;
    std::function<void(std::vector<MetricState>&)> change;
  };
  const std::vector<Tamper> tampers = {
      {"is another subset's",
       [&](std::vector<MetricState>& s) { s[0].energy.faces.push_back(foreign_face); }},
      {"is another subset's",
       [&](std::vector<MetricState>& s) {
         EnergyState& e = s[0].energy;
         e.vertices.push_back(foreign_vertex);
         e.sharp_begin.push_back(e.sharp_begin.back());
         e.listed_begin.push_back(e.listed_begin.back());
       }},
      {"is another subset's", [&](std::vector<MetricState>& s) { s[1] = s[0]; }},
      {"is not the job's",
       [&](std::vector<MetricState>& s) { s[0].energy.points.front().id = foreign_point; }},
      // A face its job's collapse removed, left out (a dead face holds no points: nothing else
      // in the state names it, and the master would keep its old points, held twice). Refused
      // by the coverage check, or before it by the points' when the master held a point on
      // that face that the job moved: the state then gives a point it does not own.
      {"does not cover face|is not the job's",
       [&](std::vector<MetricState>& s) {
         std::vector<FaceId>& faces = s[1].energy.faces;
         faces.erase(std::find(faces.begin(), faces.end(), records[1].back().fl));
       }},
      {"not in increasing order",
       [&](std::vector<MetricState>& s) {
         std::swap(s[0].energy.faces.front(), s[0].energy.faces.back());
       }},
      {"listed twice",
       [&](std::vector<MetricState>& s) {
         std::vector<FaceId>& faces = s[0].energy.faces;
         faces.insert(faces.begin() + 1, faces.front());
       }},
      // A point moved onto the face of the first run, after another face's run.
      {"not listed together",
       [&](std::vector<MetricState>& s) {
         std::vector<EnergyState::Point>& points = s[0].energy.points;
         size_t k = 1;
         while (k < points.size() && points[k].face == points[0].face) ++k;
         ++k;
         while (k < points.size() && points[k].face == points[k - 1].face) ++k;
         points.at(k).face = points[0].face;
       }},
  };
  // As one thread checks them, and in chunks (cores = 8: four per state).
  for (const unsigned cores : {0u, 8u})
    for (const Tamper& tamper : tampers) {
      std::vector<MetricState> states = honest;
      tamper.change(states);
      expect_refused_and_unchanged(
          [&] {
            import_result_states(*master, {&states[0], &states[1]}, vertex_subset, face_subset, 2,
                                 changes, cores);
          },
          tamper.what, *energy, before);
    }

  // Taken in chunks, as one_by_one takes them on one thread.
  import_result_states(*master, {&honest[0], &honest[1]}, vertex_subset, face_subset, 2, changes,
                       8);
  for (size_t k = 0; k < honest.size(); ++k)
    import_result_state(*one_by_one, honest[k], records[k]);
  const auto* other = dynamic_cast<EnergyPriority*>(one_by_one.get());
  const auto a = energy->point_states(), b = other->point_states();
  size_t moved = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].face, b[i].face) << "point " << i;
    ASSERT_EQ(a[i].parked, b[i].parked) << "point " << i;
    ASSERT_EQ(a[i].distance_sq, b[i].distance_sq) << "point " << i;
    moved += a[i].face != before[i].face || a[i].parked != before[i].parked;
  }
  EXPECT_GT(moved, 100u);
  EXPECT_EQ(energy->held_point_count(), other->held_point_count());
  const SharpCurves &ca = energy->curves(), &cb = other->curves();
  ASSERT_GT(ca.sample_count(), 0u);
  for (size_t i = 0; i < ca.sample_count(); ++i) {
    ASSERT_EQ(ca.sample_edge(i), cb.sample_edge(i)) << "curve sample " << i;
    ASSERT_EQ(ca.sample_distance_sq(i), cb.sample_distance_sq(i)) << "curve sample " << i;
  }
  for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
    ASSERT_EQ(ca.sharp_neighbors(v), cb.sharp_neighbors(v)) << "vertex " << v;
}

// The quadric's jobs return no state: the master follows their records, side by side, each
// list naming only its own subset's vertices. A record naming another subset's vertex, or
// out of range, or a state where none belongs, is refused, the master unchanged; the honest
// round leaves the master's quadrics as the jobs left theirs.
TEST(JobState, QuadricRecordsSideBySideTakeOnlyTheirOwnSubsets) {
  testing::RoundZero round("stratocaster-9k.ply", SimplifyOptions{}, 2);
  std::vector<uint32_t> vertex_subset(round.whole.vertex_capacity(), kNoId);
  std::vector<MetricState> states;
  std::vector<std::vector<CollapseRecord>> records;
  for (SubsetJob& job : round.jobs) {
    for (VertexId v = 0; v < job.mesh.vertex_count(); ++v)
      if (job.owned[v]) vertex_subset[job.global_vertex[v]] = job.subset;
    job.options.target_faces = job.mesh.face_count() / 2;
    SubsetResult result = simplify_subset(job);
    EXPECT_TRUE(result.state.empty());
    states.push_back(std::move(result.state));
    records.push_back(std::move(result.records));
  }
  ASSERT_FALSE(records[0].empty());
  ASSERT_FALSE(records[1].empty());
  const auto* q = dynamic_cast<QuadricPriority*>(round.master.get());
  ASSERT_NE(q, nullptr);
  std::vector<Quadric> before;
  for (VertexId v = 0; v < round.whole.vertex_capacity(); ++v) before.push_back(q->quadric(v));
  auto unchanged = [&] {
    for (VertexId v = 0; v < round.whole.vertex_capacity(); ++v)
      if (q->quadric(v).c != before[v].c || q->quadric(v).weight != before[v].weight) return false;
    return true;
  };
  const std::vector<uint32_t> faces = face_subsets(round.whole, vertex_subset);
  auto refused = [&](std::vector<std::vector<CollapseRecord>> lists, std::vector<MetricState> given,
                     const std::string& expected) {
    try {
      import_result_states(*round.master, {&given[0], &given[1]}, vertex_subset, faces, 2,
                           {&lists[0], &lists[1]});
      ADD_FAILURE() << expected << ": accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
    EXPECT_TRUE(unchanged()) << expected;
  };
  std::vector<std::vector<CollapseRecord>> tampered = records;
  tampered[0].back().vt = records[1].front().vs;
  refused(tampered, states, "is another subset's");
  tampered = records;
  tampered[1].front().vs = VertexId(round.whole.vertex_capacity() + 3);
  refused(tampered, states, "out of range");
  std::vector<MetricState> with_state = states;
  with_state[1].metric = "quadric";
  with_state[1].quadric.vertices.push_back(records[1].front().vs);
  with_state[1].quadric.quadrics.push_back(Quadric{});
  refused(records, with_state, "whose jobs return none");

  import_result_states(*round.master, {&states[0], &states[1]}, vertex_subset, faces, 2,
                       {&records[0], &records[1]});
  // Side by side as one at a time on a second master (ImportedStateEqualsTheReplayedState
  // checks the followed quadrics against collapsed() on every merged record).
  auto one_by_one =
      make_priority_module(SimplifyOptions{}, round.repaired.mesh, locked_vertices(round.repaired));
  one_by_one->initialize(round.whole);
  for (size_t k = 0; k < 2; ++k) import_result_state(*one_by_one, states[k], records[k]);
  const auto* o = dynamic_cast<QuadricPriority*>(one_by_one.get());
  size_t changed = 0;
  for (VertexId v = 0; v < round.whole.vertex_capacity(); ++v) {
    ASSERT_EQ(q->quadric(v).c, o->quadric(v).c) << v;
    ASSERT_EQ(q->quadric(v).weight, o->quadric(v).weight) << v;
    changed += q->quadric(v).weight != before[v].weight ? 1 : 0;
  }
  EXPECT_GT(changed, records[0].size() / 2);
}

// Two runs of one job made the same collapses: the same ends, positions and costs, bit for bit.
::testing::AssertionResult same_collapses(const SubsetResult& a, const SubsetResult& b) {
  if (a.records.size() != b.records.size())
    return ::testing::AssertionFailure()
           << a.records.size() << " collapses against " << b.records.size();
  for (size_t i = 0; i < a.records.size(); ++i) {
    const CollapseRecord &x = a.records[i], &y = b.records[i];
    if (!(x.vs == y.vs && x.vt == y.vt && x.position == y.position && x.cost == y.cost))
      return ::testing::AssertionFailure() << "collapse " << i << " differs";
  }
  return ::testing::AssertionSuccess();
}

// Round 0's quadric jobs carry no state (job_state_needed): on the input mesh a job
// initialises, over its owned vertices' whole fans, the quadrics the master would give it, so
// its collapses are the same, bit for bit.
TEST(JobState, RoundZeroQuadricJobsNeedNoState) {
  for (const char* name : {"stratocaster-9k.ply", "pymeshlab-colored-airplane-11k.ply"}) {
    testing::RoundZero round(name, SimplifyOptions{}, 3);
    ASSERT_FALSE(job_state_needed(*round.master, 0));
    ASSERT_TRUE(job_state_needed(*round.master, 1));
    size_t compared = 0;
    for (SubsetJob& job : round.jobs) {
      job.options.target_faces = job.mesh.face_count() / 3;
      SubsetJob without = job;
      without.state = MetricState{};
      const SubsetResult a = simplify_subset(job), b = simplify_subset(without);
      ASSERT_TRUE(same_collapses(a, b)) << name << " subset " << job.subset;
      compared += a.records.size();
    }
    EXPECT_GT(compared, round.whole.live_vertices() / 3) << name;
  }
}

// A quadric job's state carries the quadrics of its free vertices only (export_job_state): a
// job costs and collapses no edge with another end. Given every vertex's quadric, it makes the
// same collapses, bit for bit.
TEST(JobState, AQuadricJobCarriesItsFreeVerticesQuadricsOnly) {
  for (const char* name :
       {"stratocaster-9k.ply", "pymeshlab-colored-airplane-11k.ply", "cad-cycloidal-43k.ply"}) {
    const std::string what = name;
    testing::RoundZero round(name, options_of("quadric"), 4);
    size_t compared = 0, left_out = 0;
    for (SubsetJob& job : round.jobs) {
      job.options.target_faces = job.mesh.face_count() / 3;
      SubsetJob full = job;
      const IdMaps maps{&job.global_vertex, &job.global_face, &job.global_wedge};
      full.state.quadric = dynamic_cast<const QuadricPriority&>(*round.master).export_local(maps);
      ASSERT_EQ(full.state.quadric.vertices.size(), job.mesh.vertex_count());
      left_out += full.state.quadric.vertices.size() - job.state.quadric.vertices.size();
      const SubsetResult a = simplify_subset(job), b = simplify_subset(full);
      ASSERT_TRUE(same_collapses(a, b)) << what << " subset " << job.subset;
      compared += a.records.size();
    }
    EXPECT_GT(left_out, 0u) << what << ": every job's border carries what it never reads";
    EXPECT_GT(compared, round.whole.live_vertices() / 4) << what;
  }
}

}  // namespace
}  // namespace parapm
