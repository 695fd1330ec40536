// The collapse driver on drawn meshes: where it stops, determinism, the records it keeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <string>

#include "drawn_meshes.h"
#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "simplify/copy_groups.h"
#include "simplify/quadric_priority.h"
#include "simplify/simplifier.h"
#include "simplify/simplify.h"
#include "test_support.h"

namespace parapm {
namespace {

using testing::uv_sphere;

std::vector<CollapseRecord> simplify(const Mesh&, size_t target_faces, CollapseMesh& cm) {
  std::vector<uint8_t> locked;
  QuadricPriority priority(locked, {});
  Simplifier simplifier(cm, priority, standard_constraints(locked));
  return simplifier.run({target_faces}, {}, nullptr);
}

TEST(Simplifier, ClosedSphereGoesDownToATetrahedron) {
  const Mesh sphere = uv_sphere(12, 16);
  CollapseMesh cm(sphere);
  const auto records = simplify(sphere, 0, cm);
  EXPECT_EQ(cm.live_faces(), 4u);
  EXPECT_EQ(cm.live_vertices(), 4u);
  EXPECT_EQ(records.size(), sphere.vertex_count() - 4);
}

TEST(Simplifier, StopsAtTheTargetFaceCount) {
  const Mesh sphere = uv_sphere(12, 16);
  CollapseMesh cm(sphere);
  simplify(sphere, 100, cm);
  EXPECT_LE(cm.live_faces(), 100u);
  EXPECT_GE(cm.live_faces(), 98u);  // a closed mesh loses two faces per collapse
}

TEST(Simplifier, SameInputSameRecords) {
  const Mesh sphere = uv_sphere(10, 14);
  CollapseMesh a(sphere), b(sphere);
  const auto ra = simplify(sphere, 20, a);
  const auto rb = simplify(sphere, 20, b);
  ASSERT_EQ(ra.size(), rb.size());
  for (size_t i = 0; i < ra.size(); ++i) {
    EXPECT_EQ(ra[i].vs, rb[i].vs);
    EXPECT_EQ(ra[i].vt, rb[i].vt);
    EXPECT_EQ(ra[i].position, rb[i].position);
  }
}

TEST(Simplifier, CancellationStopsTheRun) {
  const Mesh sphere = uv_sphere(60, 80);
  CollapseMesh cm(sphere);
  std::vector<uint8_t> locked;
  QuadricPriority priority(locked, {});
  Simplifier simplifier(cm, priority, standard_constraints(locked));
  CancelToken token;
  uint64_t calls = 0;
  auto progress = [&](uint64_t, uint64_t) {
    if (++calls == 2) token.cancel();
  };
  try {
    simplifier.run({0}, progress, &token);
    FAIL() << "expected cancellation";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kCancelled);
  }
  EXPECT_GT(cm.live_faces(), 4u);
}

TEST(Simplifier, RecordsNameTheApexesOfTheRemovedFaces) {
  const Mesh sphere = uv_sphere(8, 10);
  CollapseMesh cm(sphere);
  const Mesh copy = sphere;
  const auto records = simplify(sphere, 0, cm);
  ASSERT_FALSE(records.empty());
  const CollapseRecord& first = records.front();
  // The first collapse happens on the input mesh: its faces are the input's faces.
  EXPECT_NE(first.fl, kNoId);
  EXPECT_NE(first.fr, kNoId);
  const Triangle& fl = copy.faces[first.fl];
  const int k = corner_of(fl, first.vs);
  EXPECT_EQ(fl[(k + 1) % 3], first.vt);
  EXPECT_EQ(fl[(k + 2) % 3], first.vl);
  const Triangle& fr = copy.faces[first.fr];
  const int j = corner_of(fr, first.vt);
  EXPECT_EQ(fr[(j + 1) % 3], first.vs);
  EXPECT_EQ(fr[(j + 2) % 3], first.vr);
}

// Costs an edge by its squared length, except that one edge's cost, costed for a collapse,
// has grown past its queue key (as an energy key's does when collapses beside the edge move
// points onto its star).
class GrownCost : public PriorityModule {
 public:
  GrownCost(VertexId a, VertexId b) : a_(std::min(a, b)), b_(std::max(a, b)) {}
  std::string name() const override { return "grown"; }
  void initialize(const CollapseMesh&) override {}
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    const Vec3 &p = mesh.position(a), &q = mesh.position(b);
    out.vs = a;
    out.vt = b;
    out.position = {(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2};
    out.cost = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
               (p[2] - q[2]) * (p[2] - q[2]);
    if (costing == Costing::kPerform && std::min(a, b) == a_ && std::max(a, b) == b_)
      out.cost += 1000;
    return true;
  }
  void collapsed(const CollapseMesh&, CollapseCandidate&, const EdgeFaces&) override {}

 private:
  VertexId a_, b_;
};

// An n x n grid in the plane z = 0, each vertex moved in the plane by up to a fifth of the
// spacing (a fixed pattern), two triangles per cell: every edge of its inside costs exactly
// zero with the quadric.
Mesh jittered_flat_grid(int n) {
  Mesh m;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double dx = 0.2 * std::sin(12.9898 * i + 78.233 * j);
      const double dy = 0.2 * std::cos(39.3468 * i + 11.135 * j);
      m.positions.push_back({i + dx, j + dy, 0});
    }
  auto at = [&](int i, int j) { return VertexId(j * n + i); };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      m.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      m.faces.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return m;
}

TEST(Simplifier, FlatTiesGoShortestEdgeFirst) {
  // Inside a flat grid every edge costs zero; one edge near the last ids is made the shortest.
  const int n = 8;
  Mesh grid = jittered_flat_grid(n);
  const VertexId a = VertexId((n - 2) * n + (n - 3)), b = a + 1;
  const Vec3 pa = grid.positions[a];
  grid.positions[b] = {pa[0] + 0.05, pa[1] + 0.01, 0};
  CollapseMesh cm(grid);
  const auto records = simplify(grid, grid.face_count() - 2, cm);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].cost, 0.0);
  const auto [first, second] = std::minmax(records[0].vs, records[0].vt);
  EXPECT_EQ(first, a) << "the first collapse of a flat grid is not its shortest edge";
  EXPECT_EQ(second, b);
}

TEST(Simplifier, AFlatGridSimplifiesWithoutAHub) {
  // With the ties of a flat region left to the ids, the smallest id absorbed its neighbours
  // one after the other: here a vertex of 41 faces among slivers, 6,938 vetoes for 424
  // collapses.
  const Mesh grid = jittered_flat_grid(24);
  CollapseMesh cm(grid);
  std::vector<uint8_t> locked;
  QuadricPriority priority(locked, {});
  Simplifier simplifier(cm, priority, standard_constraints(locked));
  simplifier.run({grid.face_count() / 5}, {}, nullptr);
  EXPECT_LE(cm.live_faces(), grid.face_count() / 5);
  size_t largest_fan = 0;
  for (VertexId v = 0; v < cm.vertex_capacity(); ++v)
    if (cm.vertex_alive(v)) largest_fan = std::max(largest_fan, cm.faces_of(v).size());
  EXPECT_LE(largest_fan, 16u);
  EXPECT_LT(simplifier.stats().rejected, simplifier.stats().collapses);
  std::printf("largest fan %zu faces; %llu collapses, %llu vetoed\n", largest_fan,
              (unsigned long long)simplifier.stats().collapses,
              (unsigned long long)simplifier.stats().rejected);
}

TEST(Simplifier, BoundaryFlagsAfterCollapsesAreThoseOfTheMeshBuiltAnew) {
  // A grid with a square hole: an outer and an inner border. The flags collapses keep up to
  // date (vs's and the apexes') must agree, for every vertex left, with a mesh built from the
  // live faces, and so must the faces around every vertex.
  const int n = 20;
  const Mesh grid = jittered_flat_grid(n);
  Mesh holed;
  holed.positions = grid.positions;
  for (size_t f = 0; f < grid.faces.size(); ++f) {
    const int cell = int(f / 2), i = cell % (n - 1), j = cell / (n - 1);
    if (i >= 7 && i < 11 && j >= 7 && j < 11) continue;
    holed.faces.push_back(grid.faces[f]);
  }
  for (const size_t target : {holed.face_count() / 2, holed.face_count() / 8, size_t(20)}) {
    CollapseMesh cm(holed);
    simplify(holed, target, cm);
    Mesh live;
    live.positions = holed.positions;
    for (FaceId f = 0; f < cm.face_capacity(); ++f)
      if (cm.face_alive(f)) live.faces.push_back(cm.face(f));
    const CollapseMesh anew(live);
    size_t on_border = 0;
    for (VertexId v = 0; v < cm.vertex_capacity(); ++v) {
      ASSERT_EQ(cm.vertex_alive(v), anew.vertex_alive(v)) << "target " << target << " vertex " << v;
      if (!cm.vertex_alive(v)) continue;
      EXPECT_EQ(cm.is_boundary(v), anew.is_boundary(v)) << "target " << target << " vertex " << v;
      EXPECT_EQ(cm.faces_of(v).size(), anew.faces_of(v).size()) << "target " << target;
      on_border += cm.is_boundary(v);
    }
    EXPECT_GT(on_border, 0u);
  }
}

// The first key's edge costs more now than the next key: it goes back in the queue with
// its present cost, and the cheaper collapses come first.
TEST(Simplifier, AnEdgeWhoseCostGrewGoesBackInTheQueue) {
  const Mesh sphere = uv_sphere(12, 16);
  CollapseMesh cm(sphere);
  // The edge collapsed first when no cost grows.
  CollapseMesh plain_mesh(sphere);
  GrownCost plain(kNoId, kNoId);
  Simplifier first_run(plain_mesh, plain, standard_constraints({}));
  const auto first = first_run.run({sphere.face_count() - 2}, {}, nullptr);
  ASSERT_EQ(first.size(), 1u);
  const VertexId sa = first[0].vs, sb = first[0].vt;
  GrownCost priority(sa, sb);
  std::vector<uint8_t> locked;
  Simplifier simplifier(cm, priority, standard_constraints(locked));
  const auto records = simplifier.run({sphere.face_count() - 40}, {}, nullptr);
  ASSERT_EQ(records.size(), 20u);
  EXPECT_GE(simplifier.stats().requeued, 1u);
  for (const CollapseRecord& r : records) {
    EXPECT_LT(r.cost, 1000) << "the grown edge went first";
    EXPECT_FALSE(std::min(r.vs, r.vt) == std::min(sa, sb) &&
                 std::max(r.vs, r.vt) == std::max(sa, sb));
  }
}

// Costs an edge by its squared length, a cost of its two ends alone, and counts the costings
// (queue keys and costings on top) of edges that the link condition or the boundary rule
// vetoes at that moment (`judges`: those two rules, outside the simplifier).
class LengthCost : public PriorityModule {
 public:
  LengthCost(bool costly, const std::vector<std::unique_ptr<ConstraintModule>>& judges)
      : costly_(costly), judges_(judges) {}
  std::string name() const override { return "length"; }
  void initialize(const CollapseMesh&) override {}
  bool costly() const override { return costly_; }
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    const Vec3 &p = mesh.position(a), &q = mesh.position(b);
    out.vs = std::min(a, b);
    out.vt = std::max(a, b);
    out.position = {(p[0] + q[0]) / 2, (p[1] + q[1]) / 2, (p[2] + q[2]) / 2};
    out.cost = (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
               (p[2] - q[2]) * (p[2] - q[2]);
    const EdgeFaces edge = mesh.edge_faces(a, b);
    for (const auto& judge : judges_)
      if (!judge->allows(mesh, out, edge)) {
        ++(costing == Costing::kQueue ? vetoed_keys : vetoed_on_top);
        break;
      }
    return true;
  }
  void collapsed(const CollapseMesh&, CollapseCandidate&, const EdgeFaces&) override {}
  mutable uint64_t vetoed_keys = 0;
  mutable uint64_t vetoed_on_top = 0;

 private:
  bool costly_;
  const std::vector<std::unique_ptr<ConstraintModule>>& judges_;
};

// A mesh of loose triangles (what the repair leaves of chair-dupfaces-13k, 3 edges per face,
// none collapsible: every piece is at its component minimum) holds more current queue entries
// than the stale-entry compaction's threshold (2 per live face). The compaction must not run
// again before the queue has doubled: it ran on every pop, quadratic (0.95 s for the chair's
// 12.7k faces and no collapse, 789 s for the motorbike's 332k with --free-copies).
TEST(Simplifier, LooseTrianglesDoNotCompactTheQueueOnEveryPop) {
  Mesh mesh;
  constexpr uint32_t kTriangles = 20000;
  for (uint32_t i = 0; i < kTriangles; ++i) {
    const double x = double(i % 200), y = double(i / 200);
    const VertexId v = VertexId(mesh.positions.size());
    mesh.positions.push_back({x, y, 0});
    mesh.positions.push_back({x + 0.5, y, 0});
    mesh.positions.push_back({x, y + 0.5, 0});
    mesh.faces.push_back({v, v + 1, v + 2});
  }
  CollapseMesh working(mesh);
  QuadricPriority priority({}, QuadricOptions{});
  Simplifier simplifier(working, priority, standard_constraints({}));
  const std::vector<CollapseRecord> records = simplifier.run(SimplifierLimits{}, {}, nullptr);
  EXPECT_TRUE(records.empty());
  EXPECT_EQ(simplifier.stats().rejected, 3u * kTriangles);
  EXPECT_LE(simplifier.stats().compactions, 2u);
}

// With a costly module (the energy) the simplifier checks the topological rules before it
// costs an edge on top of the queue or a vetoed edge whose star changed. Down to the legal
// minimum of a real mesh, where those rules veto thousands of edges: the module is never asked
// to cost a vetoed edge on top, it costs fewer vetoed edges' keys, and, the costs being the
// ends' alone, the collapses are exactly those of the unscreened run.
TEST(Simplifier, ACostlyModuleIsNotAskedToCostEdgesTheTopologicalRulesVeto) {
  const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data("stratocaster-9k.ply")));
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  std::vector<std::unique_ptr<ConstraintModule>> judges;
  for (auto& rule : standard_constraints(locked))
    if (rule->name() == "link-condition" || rule->name() == "boundary") {
      ASSERT_TRUE(rule->topological());
      judges.push_back(std::move(rule));
    }
  ASSERT_EQ(judges.size(), 2u);
  struct Run {
    std::vector<CollapseRecord> records;
    SimplifierStats stats;
    uint64_t vetoed_keys = 0, vetoed_on_top = 0;
    size_t faces = 0;
  };
  auto run = [&](bool costly) {
    CollapseMesh cm(repaired.mesh);
    LengthCost cost(costly, judges);
    Simplifier simplifier(cm, cost, standard_constraints(locked));
    Run r;
    r.records = simplifier.run({0}, {}, nullptr);
    r.stats = simplifier.stats();
    r.vetoed_keys = cost.vetoed_keys;
    r.vetoed_on_top = cost.vetoed_on_top;
    r.faces = cm.live_faces();
    return r;
  };
  const Run plain = run(false);
  const Run screened = run(true);
  EXPECT_GT(plain.vetoed_on_top, 500u) << "the rules veto few edges here: a weak test";
  EXPECT_EQ(plain.stats.screened, 0u);
  EXPECT_EQ(screened.vetoed_on_top, 0u);
  EXPECT_LT(screened.vetoed_keys, plain.vetoed_keys * 4 / 5);
  EXPECT_GT(screened.stats.screened, 0u);
  EXPECT_LT(screened.stats.evaluations, plain.stats.evaluations);
  EXPECT_EQ(screened.faces, plain.faces);
  ASSERT_EQ(screened.records.size(), plain.records.size());
  for (size_t i = 0; i < plain.records.size(); ++i) {
    const CollapseRecord &x = plain.records[i], &y = screened.records[i];
    ASSERT_TRUE(x.vs == y.vs && x.vt == y.vt && x.position == y.position && x.cost == y.cost)
        << "collapse " << i << " differs";
  }
}

// The quadric with its queue keys declared to read the edges' stars: the simplifier then
// queues every edge uncosted for its collapse, as it does for such a module.
class KeysReadTheStar : public PriorityWrapper {
 public:
  using PriorityWrapper::PriorityWrapper;
  bool queue_key_of_ends_only() const override { return false; }
};

// An edge whose queue key is at or below the last collapse's is costed for its collapse as it
// is queued, and one its star's rules veto waits among the vetoed edges (Simplifier::
// queue_checked). On a CAD part taken to its legal minimum (thin fans whose collapses fold:
// tens of thousands of vetoes; seam collapses; a cost ceiling), the collapses are exactly those of
// the run that queues every edge and vetoes it when it comes out.
TEST(Simplifier, EdgesVetoedAsTheyAreQueuedLeaveTheSameRun) {
  const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data("cad-cycloidal-43k.ply")));
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  const CopyGroups groups = copy_groups(repaired);
  auto run = [&](bool keys_of_ends_only, double max_cost) {
    CollapseMesh cm(repaired.mesh);
    QuadricPriority quadric(locked, QuadricOptions{});
    KeysReadTheStar star_keys(quadric);
    PriorityModule& priority =
        keys_of_ends_only ? static_cast<PriorityModule&>(quadric) : star_keys;
    Simplifier simplifier(cm, priority, standard_constraints(locked));
    simplifier.join_copies(&groups);
    SimplifierLimits limits;
    limits.max_cost = max_cost;
    std::vector<CollapseRecord> records = simplifier.run(limits, {}, nullptr);
    return std::make_pair(std::move(records), simplifier.stats());
  };
  const double unlimited = std::numeric_limits<double>::infinity();
  const auto [all, all_stats] = run(false, unlimited);
  ASSERT_GT(all.size(), 100u);
  for (const double ceiling : {unlimited, all[all.size() / 2].cost}) {
    const auto [queued, queued_stats] = run(false, ceiling);
    const auto [checked, checked_stats] = run(true, ceiling);
    std::printf("ceiling %g: %zu collapses, %llu vetoed (%llu as queued) against %llu\n", ceiling,
                checked.size(), (unsigned long long)checked_stats.rejected,
                (unsigned long long)checked_stats.vetoed_when_queued,
                (unsigned long long)queued_stats.rejected);
    EXPECT_EQ(queued_stats.vetoed_when_queued, 0u);
    EXPECT_GT(checked_stats.vetoed_when_queued, 1000u) << "few vetoes as queued: a weak test";
    EXPECT_GT(checked_stats.seam_collapses, 0u);
    EXPECT_EQ(checked_stats.stop_reason, queued_stats.stop_reason);
    ASSERT_EQ(checked.size(), queued.size()) << "ceiling " << ceiling;
    for (size_t i = 0; i < queued.size(); ++i) {
      const CollapseRecord &x = queued[i], &y = checked[i];
      ASSERT_TRUE(x.vs == y.vs && x.vt == y.vt && x.position == y.position && x.cost == y.cost &&
                  x.error == y.error)
          << "ceiling " << ceiling << ": collapse " << i << " differs";
    }
  }
}

// A rule, forwarded, with the number of its answers counted; the face of its fold vetoes
// forgotten unless `tells_the_fold`.
class CountedRule : public ConstraintModule {
 public:
  CountedRule(std::unique_ptr<ConstraintModule> inner, bool tells_the_fold, uint64_t& answers)
      : inner_(std::move(inner)), tells_the_fold_(tells_the_fold), answers_(answers) {}
  std::string name() const override { return inner_->name(); }
  void initialize(const CollapseMesh& mesh) override { inner_->initialize(mesh); }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& candidate,
              const EdgeFaces& edge) const override {
    ++answers_;
    return inner_->allows(mesh, candidate, edge);
  }
  FaceId folded_face() const override { return tells_the_fold_ ? inner_->folded_face() : kNoId; }
  bool topological() const override { return inner_->topological(); }
  bool star_local() const override { return inner_->star_local(); }
  void drop_too_small(const CollapseMesh& mesh, std::vector<SeamPair>& collapses) const override {
    inner_->drop_too_small(mesh, collapses);
  }
  void collapsed(const CollapseMesh& mesh, const CollapseCandidate& c) override {
    inner_->collapsed(mesh, c);
  }

 private:
  std::unique_ptr<ConstraintModule> inner_;
  bool tells_the_fold_;
  uint64_t& answers_;
};

// The quadric, with the rules that read the edge alone not asked before the costing for its
// collapse (PriorityModule::placed_when_queued_is_placed).
class RulesAfterTheCosting : public PriorityWrapper {
 public:
  using PriorityWrapper::PriorityWrapper;
  bool placed_when_queued_is_placed() const override { return false; }
};

// The same, and no queue costing taken for the collapse's own (CollapseCandidate::
// as_performed): the simplifier costs every edge it checks as queued again, then asks the rules.
class EveryCheckCosted : public RulesAfterTheCosting {
 public:
  using RulesAfterTheCosting::RulesAfterTheCosting;
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    const bool placed = inner_.evaluate(mesh, a, b, out, costing);
    out.as_performed = costing == Costing::kPerform;
    return placed;
  }
};

// An edge checked as it is queued takes the queue's costing when the module says it is the
// collapse's own (the quadric placed freely); one vetoed by a fold is tested first on the face
// that folded (ConstraintModule::folded_face), which vetoes most of them again; below the
// quadric's line the rules that read the edge alone come before the costing for its collapse
// (they veto most edges retried there). On the CAD part of thin fans taken to its legal
// minimum, the same collapses as costing every checked edge again and asking every rule after,
// with fewer costings and fewer answers; each shortcut saves costings of its own.
TEST(Simplifier, AVetoedEdgeIsTestedFirstOnTheFaceThatFoldedIt) {
  const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data("cad-cycloidal-43k.ply")));
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  const CopyGroups groups = copy_groups(repaired);
  struct Run {
    std::vector<CollapseRecord> records;
    SimplifierStats stats;
    uint64_t answers = 0;
  };
  enum class Shortcuts { kNone, kAllButRulesFirst, kAll };
  auto run = [&](Shortcuts shortcuts) {
    CollapseMesh cm(repaired.mesh);
    QuadricOptions options;
    options.free_placement_above_faces = free_placement_line(cm.live_faces());
    QuadricPriority quadric(locked, options);
    EveryCheckCosted every_check_costed(quadric);
    RulesAfterTheCosting rules_after(quadric);
    PriorityModule& priority = shortcuts == Shortcuts::kAll ? static_cast<PriorityModule&>(quadric)
                               : shortcuts == Shortcuts::kNone
                                   ? static_cast<PriorityModule&>(every_check_costed)
                                   : rules_after;
    Run r;
    std::vector<std::unique_ptr<ConstraintModule>> rules;
    for (auto& rule : standard_constraints(locked))
      rules.push_back(
          std::make_unique<CountedRule>(std::move(rule), shortcuts != Shortcuts::kNone, r.answers));
    Simplifier simplifier(cm, priority, std::move(rules));
    simplifier.join_copies(&groups);
    r.records = simplifier.run({0}, {}, nullptr);
    r.stats = simplifier.stats();
    return r;
  };
  const Run plain = run(Shortcuts::kNone);
  const Run rules_after = run(Shortcuts::kAllButRulesFirst);
  const Run quick = run(Shortcuts::kAll);
  std::printf(
      "%zu collapses, %llu vetoed as queued: %llu -> %llu -> %llu evaluations, %llu -> %llu "
      "rule answers\n",
      quick.records.size(), (unsigned long long)quick.stats.vetoed_when_queued,
      (unsigned long long)plain.stats.evaluations,
      (unsigned long long)rules_after.stats.evaluations,
      (unsigned long long)quick.stats.evaluations, (unsigned long long)plain.answers,
      (unsigned long long)quick.answers);
  EXPECT_GT(plain.stats.vetoed_when_queued, 10000u) << "few vetoes as queued: a weak test";
  EXPECT_LT(quick.stats.evaluations, plain.stats.evaluations * 9 / 10);
  EXPECT_LT(quick.stats.evaluations + 1000, rules_after.stats.evaluations);
  EXPECT_LT(quick.answers, plain.answers * 3 / 4);
  for (const Run* other : {&plain, &rules_after}) {
    EXPECT_EQ(quick.stats.vetoed_when_queued, other->stats.vetoed_when_queued);
    EXPECT_EQ(quick.stats.stop_reason, other->stats.stop_reason);
    ASSERT_EQ(quick.records.size(), other->records.size());
    for (size_t i = 0; i < other->records.size(); ++i) {
      const CollapseRecord &x = other->records[i], &y = quick.records[i];
      ASSERT_TRUE(x.vs == y.vs && x.vt == y.vt && x.position == y.position && x.cost == y.cost &&
                  x.error == y.error)
          << "collapse " << i << " differs";
    }
  }
}

// twin_faces() is edge_faces() of every live corner's edge, in one pass: on a real mesh with
// boundaries and seams, before and after collapses (dead faces and emptied fans).
TEST(Simplifier, TwinFacesAreTheEdgesFacesOfEveryCorner) {
  const RepairedMesh repaired =
      repair_mesh(read_mesh(testing::test_data("pymeshlab-bunny-textured-10k.obj")));
  CollapseMesh cm(repaired.mesh);
  auto expect_twins = [&](const char* when) {
    const std::vector<FaceId> twin = cm.twin_faces();
    ASSERT_EQ(twin.size(), 3 * cm.face_capacity());
    size_t boundary = 0;
    for (FaceId f = 0; f < cm.face_capacity(); ++f)
      for (int k = 0; k < 3; ++k) {
        const FaceId got = twin[3 * size_t(f) + size_t(k)];
        if (!cm.face_alive(f)) {
          ASSERT_EQ(got, kNoId) << when << ": dead face " << f;
          continue;
        }
        const Triangle& t = cm.face(f);
        ASSERT_EQ(got, cm.edge_faces(t[(k + 1) % 3], t[k]).left) << when << ": face " << f;
        boundary += got == kNoId;
      }
    EXPECT_GT(boundary, 0u) << when << ": no boundary edge, a weak test";
  };
  expect_twins("input");
  QuadricPriority priority(locked_vertices(repaired), QuadricOptions{});
  Simplifier simplifier(cm, priority, standard_constraints(locked_vertices(repaired)));
  SimplifierLimits limits;
  limits.target_faces = cm.live_faces() / 3;
  ASSERT_FALSE(simplifier.run(limits, {}, nullptr).empty());
  expect_twins("after collapses");
}

// A module that costs only the edges with an end in a band (as the parallel build's band pass
// does) gives the same run whether the first queue holds every edge of the mesh or only the
// band's (SimplifierLimits::first_queue_around), and costs far fewer edges.
TEST(Simplifier, AFirstQueueAroundTheBandGivesTheSameRun) {
  class BandOnly : public PriorityWrapper {
   public:
    BandOnly(PriorityModule& inner, std::vector<uint8_t> band)
        : PriorityWrapper(inner), band_(std::move(band)) {}
    bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                  Costing costing) override {
      return (band_[a] || band_[b]) && inner_.evaluate(mesh, a, b, out, costing);
    }
    void collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                   const EdgeFaces& edge) override {
      band_[done.vs] = band_[done.vt] = 0;  // as the band pass: the band is done once collapsed
      inner_.collapsed(mesh, done, edge);
    }

   private:
    std::vector<uint8_t> band_;
  };
  const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data("stratocaster-9k.ply")));
  // The band: a slab of the model, across its middle.
  const Box box = bounding_box(repaired.mesh);
  const double middle = 0.5 * (box.min[0] + box.max[0]), width = 0.06 * (box.max[0] - box.min[0]);
  std::vector<uint8_t> band(repaired.mesh.vertex_count(), 0);
  std::vector<VertexId> listed;
  for (VertexId v = 0; v < repaired.mesh.vertex_count(); ++v)
    if (std::abs(repaired.mesh.positions[v][0] - middle) < width) {
      band[v] = 1;
      listed.push_back(v);
    }
  ASSERT_GT(listed.size(), 20u);
  auto run = [&](bool around) {
    CollapseMesh cm(repaired.mesh);
    QuadricPriority quadric(locked_vertices(repaired), QuadricOptions{});
    BandOnly priority(quadric, band);
    Simplifier simplifier(cm, priority, standard_constraints(locked_vertices(repaired)));
    SimplifierLimits limits;
    if (around) limits.first_queue_around = &listed;
    std::vector<CollapseRecord> records = simplifier.run(limits, {}, nullptr);
    return std::make_pair(std::move(records), simplifier.stats().evaluations);
  };
  const auto [all_records, all_evaluations] = run(false);
  const auto [band_records, band_evaluations] = run(true);
  EXPECT_GT(all_records.size(), 10u);
  ASSERT_EQ(band_records.size(), all_records.size());
  for (size_t i = 0; i < all_records.size(); ++i) {
    const CollapseRecord &x = all_records[i], &y = band_records[i];
    ASSERT_TRUE(x.vs == y.vs && x.vt == y.vt && x.position == y.position && x.cost == y.cost)
        << "collapse " << i << " differs";
  }
  std::printf("band of %zu vertices: %llu costings from every edge, %llu from the band's\n",
              listed.size(), (unsigned long long)all_evaluations,
              (unsigned long long)band_evaluations);
  EXPECT_LT(band_evaluations * 4, all_evaluations);
}

// The size rule with the components found once, before some collapses (as the parallel build's
// band passes and final pass take them), decides as it does finding them anew: a second run,
// down to where the rule stops every component, performs the same collapses either way.
TEST(Simplifier, ComponentsFoundBeforeCollapsesDecideAsFoundAnew) {
  const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data("stratocaster-9k.ply")));
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  CollapseMesh before(repaired.mesh);
  auto found = std::make_shared<std::vector<uint32_t>>();
  const uint32_t components = connected_components(before, *found);
  ASSERT_GE(components, 3u) << "a mesh of one piece would not test the rule";
  auto run = [&](std::shared_ptr<const std::vector<uint32_t>> given) {
    CollapseMesh cm(repaired.mesh);
    QuadricPriority priority(locked, QuadricOptions{});
    Simplifier first(cm, priority, standard_constraints(locked, given));
    first.run({cm.live_faces() / 2}, {}, nullptr);
    Simplifier second(cm, priority, standard_constraints(locked, given));
    std::vector<CollapseRecord> records = second.run({0}, {}, nullptr);
    return std::make_pair(std::move(records), cm.live_faces());
  };
  const auto [anew, anew_faces] = run(nullptr);
  const auto [given, given_faces] = run(found);
  EXPECT_GT(anew.size(), 100u);
  EXPECT_EQ(given_faces, anew_faces);
  ASSERT_EQ(given.size(), anew.size());
  for (size_t i = 0; i < anew.size(); ++i)
    ASSERT_TRUE(given[i].vs == anew[i].vs && given[i].vt == anew[i].vt &&
                given[i].position == anew[i].position)
        << "collapse " << i << " differs";
  std::printf("%u components; the second run: %zu collapses down to %zu faces\n", components,
              anew.size(), anew_faces);
  // Components of another mesh are refused, not read out of range.
  CollapseMesh cm(repaired.mesh);
  QuadricPriority priority(locked, QuadricOptions{});
  auto other = std::make_shared<std::vector<uint32_t>>(found->size() / 2, 0u);
  Simplifier wrong(cm, priority, standard_constraints(locked, other));
  EXPECT_THROW(wrong.run({0}, {}, nullptr), Error);
}

// A cost ceiling (SimplifierLimits::max_cost) on a real mesh, both metrics: the run makes the
// unlimited run's collapses up to the first that costs more, never one that costs more, and
// ends at the ceiling. (With the energy a deferred edge whose last key was above twice the
// ceiling is not costed again: the run may end a little earlier than the first such collapse.)
TEST(Simplifier, ACostCeilingTakesTheCollapsesBelowItInOrder) {
  const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data("stratocaster-9k.ply")));
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  for (const char* metric : {"quadric", "energy"}) {
    SimplifyOptions options;
    options.metric = metric;
    auto run = [&](double max_cost) {
      CollapseMesh cm(repaired.mesh);
      std::unique_ptr<PriorityModule> priority =
          make_priority_module(options, repaired.mesh, locked);
      Simplifier simplifier(cm, *priority, standard_constraints(locked));
      SimplifierLimits limits;
      limits.max_cost = max_cost;
      limits.defer_above_faces = defer_recosting_line(repaired.mesh.face_count());
      std::vector<CollapseRecord> records = simplifier.run(limits, {}, nullptr);
      return std::make_pair(std::move(records), simplifier.stats());
    };
    const auto [unlimited, unlimited_stats] = run(std::numeric_limits<double>::infinity());
    // The cost of the collapse that ends the first third of the unlimited run.
    const double ceiling = unlimited[unlimited.size() / 3].cost;
    const auto [limited, stats] = run(ceiling);
    size_t first_above = 0;
    while (first_above < unlimited.size() && unlimited[first_above].cost <= ceiling) ++first_above;
    std::printf(
        "%-8s ceiling %.3g: %zu collapses (the unlimited run's first %zu below it), %llu "
        "costed above it\n",
        metric, ceiling, limited.size(), first_above, (unsigned long long)stats.over_ceiling);
    EXPECT_EQ(stats.stop_reason, "cost ceiling reached") << metric;
    // Most of the unlimited run's collapses below the ceiling (all of them, without deferral).
    ASSERT_GE(limited.size(), first_above * 9 / 10) << metric;
    for (const CollapseRecord& r : limited) ASSERT_LE(r.cost, ceiling) << metric;
    const size_t same = std::min(first_above, limited.size());
    for (size_t i = 0; i < same; ++i) {
      const CollapseRecord &x = unlimited[i], &y = limited[i];
      ASSERT_TRUE(x.vs == y.vs && x.vt == y.vt && x.position == y.position && x.cost == y.cost)
          << metric << " collapse " << i;
    }
    if (std::string(metric) == "quadric") {  // nothing deferred: every cheaper collapse taken
      EXPECT_GE(limited.size(), first_above);
    }
  }
}

// A simplifier over a repaired mesh with `metric`'s module and the standard rules, the repair's
// copies joined (seam collapses).
struct JoinedCopies {
  JoinedCopies(const RepairedMesh& repaired, const char* metric, const std::vector<uint8_t>& locked,
               const CopyGroups& groups)
      : mesh(repaired.mesh),
        priority(make_priority_module(metric_options(metric), repaired.mesh, locked)),
        simplifier(mesh, *priority, standard_constraints(locked)) {
    simplifier.join_copies(&groups);
  }
  static SimplifyOptions metric_options(const char* metric) {
    SimplifyOptions options;
    options.metric = metric;
    return options;
  }
  CollapseMesh mesh;
  std::unique_ptr<PriorityModule> priority;
  Simplifier simplifier;
};

// A seam's queue costing reads its two groups only, not the copies it is queued on: the first
// queue costs each seam once for all the edges between its groups (Simplifier::queue_entry).
// Every edge between the copies of two groups costs the same, before any collapse and midway,
// with either metric.
TEST(Simplifier, ASeamCostsTheSameFromEveryEdgeBetweenItsGroups) {
  const RepairedMesh repaired = repair_mesh(testing::plane_with_fin(16, 3, 12, 3));
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  const CopyGroups groups = copy_groups(repaired);
  for (const char* metric : {"quadric", "energy"}) {
    for (const size_t target : {repaired.mesh.face_count(), repaired.mesh.face_count() / 2}) {
      JoinedCopies run(repaired, metric, locked, groups);
      const CollapseMesh& cm = run.mesh;
      Simplifier& simplifier = run.simplifier;
      simplifier.run({target}, {}, nullptr);
      struct Seen {
        bool placed;
        double cost;
      };
      std::map<std::pair<uint32_t, uint32_t>, Seen> seams;
      size_t shared = 0;
      std::vector<VertexId> ring;
      for (VertexId a = 0; a < cm.vertex_capacity(); ++a) {
        if (!cm.vertex_alive(a) || !groups.is_copy(a)) continue;
        cm.neighbors(a, ring);
        for (const VertexId b : ring) {
          if (b < a || !groups.is_copy(b)) continue;
          CollapseCandidate c;
          const bool placed = simplifier.cost_now(a, b, Costing::kQueue, c);
          const auto [at, first] =
              seams.try_emplace({groups.group[a], groups.group[b]}, Seen{placed, c.cost});
          if (first) continue;
          ++shared;
          ASSERT_EQ(placed, at->second.placed) << metric << " edge " << a << "-" << b;
          if (placed) {
            ASSERT_EQ(c.cost, at->second.cost) << metric << " edge " << a << "-" << b;
          }
        }
      }
      EXPECT_GT(shared, 10u) << metric << ": few seams with two edges, a weak test";
    }
  }
}

// Seam collapses whose rings overlap (a fin standing on a plane, along a line that ends inside
// it: near the line's ends the plane's two sides share the survivor) are tried in turn first,
// and none stops halfway: at the end every group's live copies (but those of parts too small
// to shrink) are at one place, with either metric.
TEST(Simplifier, SeamCollapsesWithOverlappingRingsAreTriedInTurn) {
  const RepairedMesh repaired = repair_mesh(testing::plane_with_fin(16, 3, 12, 3));
  ASSERT_GT(repaired.report.vertex_copies_added, 10u);
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  const CopyGroups groups = copy_groups(repaired);
  for (const char* metric : {"quadric", "energy"}) {
    JoinedCopies run(repaired, metric, locked, groups);
    const CollapseMesh& cm = run.mesh;
    Simplifier& simplifier = run.simplifier;
    SimplifierLimits limits;
    limits.target_faces = 40;
    simplifier.run(limits, {}, nullptr);
    const SimplifierStats& stats = simplifier.stats();
    EXPECT_GT(stats.seams_in_turn, 0u) << metric;
    EXPECT_GT(stats.seam_collapses, stats.seams_in_turn) << metric;
    EXPECT_EQ(stats.seams_split, 0u) << metric;
    size_t apart = 0;
    for (uint32_t g = 0; g + 1 < groups.offsets.size(); ++g) {
      const Vec3* place = nullptr;
      for (VertexId copy : groups.of(g)) {
        if (!cm.vertex_alive(copy)) continue;
        if (!place) place = &cm.position(copy);
        apart += cm.position(copy) != *place;
      }
    }
    EXPECT_EQ(apart, 0u) << metric << ": copies of a group apart";
    std::printf("%s: %zu faces left, %llu seam collapses, %llu of them tried in turn\n", metric,
                cm.live_faces(), (unsigned long long)stats.seam_collapses,
                (unsigned long long)stats.seams_in_turn);
  }
}

}  // namespace
}  // namespace parapm
