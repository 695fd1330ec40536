// Queue keys carried between rounds (engine/parallel/edge_keys.h), on real meshes: a carried
// key answers the first queue costing of its edge unless a collapse has changed an end of it,
// every other costing is the module's, and a job given the keys its own costing would give
// simplifies exactly as without them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <set>

#include "parallel/edge_keys.h"
#include "parallel/job_state.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "parallel_test_support.h"
#include "simplify/simplifier.h"
#include "simplify/simplify.h"

namespace parapm {
namespace {

bool same_cost(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

// Every edge once, a < b.
std::vector<std::pair<VertexId, VertexId>> edges_of(const CollapseMesh& mesh) {
  std::set<std::pair<VertexId, VertexId>> edges;
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!mesh.face_alive(f)) continue;
    const Triangle& t = mesh.face(f);
    for (int k = 0; k < 3; ++k)
      edges.insert({std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])});
  }
  return {edges.begin(), edges.end()};
}

// A test mesh, repaired, and an energy module for it (not initialised).
struct EnergyOnMesh {
  static SimplifyOptions energy() {
    SimplifyOptions options;
    options.metric = "energy";
    return options;
  }
  explicit EnergyOnMesh(const char* name)
      : repaired(testing::repaired_test_mesh(name)),
        locked(locked_vertices(repaired)),
        module(make_priority_module(energy(), repaired.mesh, locked)) {}
  RepairedMesh repaired;
  std::vector<uint8_t> locked;
  std::unique_ptr<PriorityModule> module;
};

TEST(EdgeKeys, ACarriedKeyAnswersOnceUntilAnEndOfItsEdgeChanges) {
  for (const char* metric : {"energy", "quadric"}) {
    const RepairedMesh repaired = testing::repaired_test_mesh("stratocaster-9k.ply");
    SimplifyOptions options;
    options.metric = metric;
    const std::vector<uint8_t> locked = locked_vertices(repaired);
    CollapseMesh mesh(repaired.mesh);
    std::unique_ptr<PriorityModule> module = make_priority_module(options, repaired.mesh, locked);
    module->initialize(mesh);

    // Keys that are not the module's (its own costs plus one), so that an answer from a key
    // and a costing are told apart.
    std::vector<EdgeKey> carried;
    for (auto [a, b] : edges_of(mesh)) {
      CollapseCandidate c;
      if (module->evaluate(mesh, a, b, c, Costing::kQueue)) carried.push_back({a, b, c.cost + 1});
    }
    KeyMemo memo(*module, mesh.vertex_capacity());
    memo.reset(carried);

    // Collapses through the memo, as the simplifier performs them: every 7th edge that is
    // still there, legal and placed.
    const auto constraints = standard_constraints(locked);
    for (auto& c : constraints) c->initialize(mesh);
    std::vector<uint8_t> changed(mesh.vertex_capacity(), 0);
    size_t collapses = 0, index = 0;
    for (auto [a, b] : edges_of(mesh)) {
      if (index++ % 7 != 0 || !mesh.vertex_alive(a) || !mesh.vertex_alive(b)) continue;
      CollapseCandidate c;
      if (!memo.evaluate(mesh, a, b, c, Costing::kPerform)) continue;
      const EdgeFaces edge = mesh.edge_faces(c.vs, c.vt);
      if (edge.left == kNoId && edge.right == kNoId) continue;
      bool legal = true;
      for (const auto& constraint : constraints) legal = legal && constraint->allows(mesh, c, edge);
      if (!legal) continue;
      c.vs_before = mesh.position(c.vs);
      mesh.collapse(c.vs, c.vt, c.position, edge);
      memo.collapsed(mesh, c, edge);
      for (const auto& constraint : constraints) constraint->collapsed(mesh, c);
      changed[c.vs] = changed[c.vt] = 1;
      ++collapses;
    }
    ASSERT_GT(collapses, 200u) << metric;
    EXPECT_EQ(memo.reused(), 0u) << "a performed costing never takes a key";

    // The first queue costing of an edge with both ends unchanged takes its carried key; any
    // other costing is the module's, of the mesh as it is now.
    size_t answered = 0, costed = 0;
    for (auto [a, b] : edges_of(mesh)) {
      const auto key = std::lower_bound(
          carried.begin(), carried.end(), EdgeKey{a, b, 0},
          [](const EdgeKey& x, const EdgeKey& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
      const bool was_carried = key != carried.end() && key->a == a && key->b == b;
      for (int ask = 0; ask < 2; ++ask) {
        CollapseCandidate from_memo, fresh;
        const bool placed = memo.evaluate(mesh, a, b, from_memo, Costing::kQueue);
        const bool placed_fresh = module->evaluate(mesh, a, b, fresh, Costing::kQueue);
        if (ask == 0 && was_carried && !changed[a] && !changed[b]) {
          ASSERT_TRUE(placed && same_cost(from_memo.cost, key->cost))
              << metric << " " << a << "-" << b;
          ++answered;
          continue;
        }
        ASSERT_EQ(placed, placed_fresh) << metric << " " << a << "-" << b;
        if (placed) {
          ASSERT_TRUE(same_cost(from_memo.cost, fresh.cost)) << metric << " " << a << "-" << b;
        }
        if (ask == 0) ++costed;
      }
    }
    EXPECT_EQ(memo.reused(), answered) << metric;
    EXPECT_GT(answered, 1000u) << metric;
    EXPECT_GT(costed, 1000u) << metric;
    // The memo's current keys are edges of the mesh.
    for (const EdgeKey& k : memo.current_keys(mesh)) {
      const EdgeFaces e = mesh.edge_faces(k.a, k.b);
      ASSERT_TRUE(e.left != kNoId || e.right != kNoId) << k.a << "-" << k.b;
    }
    std::printf("%-8s %zu collapses: %zu edges answered from carried keys, %zu costed\n", metric,
                collapses, answered, costed);
  }
}

// Edges costed together (evaluate_each) take their carried keys, and leave their keys, as
// costed one after the other: the first asking of every edge answered from its key, the
// second costed by the module; the same current keys after.
TEST(EdgeKeys, EdgesCostedTogetherAnswerAsOneAfterAnother) {
  const EnergyOnMesh energy("stratocaster-9k.ply");
  CollapseMesh mesh(energy.repaired.mesh);
  PriorityModule* module = energy.module.get();
  module->initialize(mesh);
  std::vector<EdgeCosting> edges;
  std::vector<EdgeKey> carried;
  size_t index = 0;
  for (auto [a, b] : edges_of(mesh)) {
    edges.push_back({a, b, false, {}});
    CollapseCandidate c;
    // Keys not the module's (its cost plus one), for every other edge.
    if (index++ % 2 == 0 && module->evaluate(mesh, a, b, c, Costing::kQueue))
      carried.push_back({a, b, c.cost + 1});
  }
  KeyMemo one(*module, mesh.vertex_capacity()), together(*module, mesh.vertex_capacity());
  one.reset(carried);
  together.reset(carried);
  for (int ask = 0; ask < 2; ++ask) {
    together.evaluate_each(mesh, edges, Costing::kQueue);
    for (const EdgeCosting& e : edges) {
      CollapseCandidate c;
      ASSERT_EQ(one.evaluate(mesh, e.a, e.b, c, Costing::kQueue), e.placed) << e.a << "-" << e.b;
      if (e.placed) {
        ASSERT_TRUE(same_cost(c.cost, e.candidate.cost)) << e.a << "-" << e.b;
      }
    }
    EXPECT_EQ(together.reused(), one.reused());
  }
  EXPECT_EQ(one.reused(), carried.size());
  const std::vector<EdgeKey> kept = one.current_keys(mesh),
                             kept_together = together.current_keys(mesh);
  ASSERT_EQ(kept.size(), kept_together.size());
  for (size_t i = 0; i < kept.size(); ++i) {
    EXPECT_EQ(kept[i].a, kept_together[i].a);
    EXPECT_EQ(kept[i].b, kept_together[i].b);
    EXPECT_TRUE(same_cost(kept[i].cost, kept_together[i].cost));
  }
}

// A round-0 job given its free edges' keys as the master costs them (exactly what it would
// cost itself) makes the same collapses, the same returned state and keys, and answers its
// first costing of every one of them from the keys.
TEST(EdgeKeys, AJobGivenFreshKeysSimplifiesAsWithout) {
  for (const char* name : {"pymeshlab-bunny-textured-10k.obj", "stratocaster-9k.ply"}) {
    SimplifyOptions options;
    options.metric = "energy";
    testing::RoundZero round(name, options, 3);
    SubsetJob& job = round.jobs[1];
    job.options.target_faces = job.mesh.face_count() / 2;
    const SubsetResult without = simplify_subset(job);
    job.keys = testing::fresh_keys(*round.master, round.whole, job);
    ASSERT_GT(job.keys.size(), 1000u) << name;
    const SubsetResult with = simplify_subset(job);

    EXPECT_EQ(without.keys_reused, 0u) << name;
    EXPECT_GE(with.keys_reused, job.keys.size()) << name;
    ASSERT_EQ(with.records.size(), without.records.size()) << name;
    for (size_t i = 0; i < with.records.size(); ++i) {
      const CollapseRecord &x = with.records[i], &y = without.records[i];
      ASSERT_TRUE(x.vs == y.vs && x.vt == y.vt && same_cost(x.cost, y.cost) &&
                  x.position == y.position)
          << name << " record " << i;
    }
    ASSERT_EQ(with.keys.size(), without.keys.size()) << name;
    for (size_t i = 0; i < with.keys.size(); ++i)
      ASSERT_TRUE(with.keys[i].a == without.keys[i].a && with.keys[i].b == without.keys[i].b &&
                  same_cost(with.keys[i].cost, without.keys[i].cost))
          << name << " key " << i;
    std::printf("%-36s job of %zu faces: %zu keys given, %llu answered, %zu collapses alike\n",
                name, job.mesh.face_count(), job.keys.size(), (unsigned long long)with.keys_reused,
                with.records.size());
  }
}

// The edges a run leaves deferred (Simplifier::deferred_edges) are live edges, each with the
// key it was deferred from. Another run of the same module on the mesh, given them
// (SimplifierLimits::first_deferred), queues them deferred without costing them while it
// defers, and holds them exactly as the first run left them; not deferring, it costs them.
TEST(DeferredEdges, ARunGivenTheDeferredEdgesQueuesThemUncosted) {
  const EnergyOnMesh energy("stratocaster-9k.ply");
  const std::vector<uint8_t>& locked = energy.locked;
  CollapseMesh mesh(energy.repaired.mesh);
  PriorityModule* module = energy.module.get();
  Simplifier first(mesh, *module, standard_constraints(locked));
  SimplifierLimits limits;
  limits.defer_above_faces = 0;
  limits.target_faces = mesh.live_faces() * 3 / 5;
  ASSERT_GT(first.run(limits, {}, nullptr).size(), 1000u);
  const std::vector<DeferredEdge> deferred = first.deferred_edges();
  ASSERT_GT(deferred.size(), 200u);
  for (size_t i = 0; i < deferred.size(); ++i) {
    const DeferredEdge& d = deferred[i];
    ASSERT_TRUE(d.a < d.b && !std::isnan(d.key)) << i;
    if (i > 0) {
      ASSERT_TRUE(deferred[i - 1].a < d.a || (deferred[i - 1].a == d.a && deferred[i - 1].b < d.b))
          << "sorted, once each: " << i;
    }
    const EdgeFaces e = mesh.edge_faces(d.a, d.b);
    ASSERT_TRUE(mesh.vertex_alive(d.a) && mesh.vertex_alive(d.b) &&
                (e.left != kNoId || e.right != kNoId))
        << d.a << "-" << d.b;
  }
  const size_t edges = edges_of(mesh).size();

  // Stopped before its first collapse: only the first queue is built.
  std::unique_ptr<PriorityModule> continued = without_initialize(*module);
  SimplifierLimits again;
  again.target_faces = mesh.live_faces();
  again.first_deferred = &deferred;
  again.defer_above_faces = 0;
  Simplifier second(mesh, *continued, standard_constraints(locked));
  ASSERT_TRUE(second.run(again, {}, nullptr).empty());
  EXPECT_EQ(second.stats().evaluations, edges - deferred.size());
  EXPECT_EQ(second.stats().deferred, deferred.size());
  const std::vector<DeferredEdge> held = second.deferred_edges();
  ASSERT_EQ(held.size(), deferred.size());
  for (size_t i = 0; i < held.size(); ++i)
    ASSERT_TRUE(held[i].a == deferred[i].a && held[i].b == deferred[i].b &&
                std::memcmp(&held[i].key, &deferred[i].key, sizeof(float)) == 0)
        << i;

  // Not deferring (below its line), every edge is costed.
  again.defer_above_faces = SIZE_MAX;
  Simplifier third(mesh, *continued, standard_constraints(locked));
  ASSERT_TRUE(third.run(again, {}, nullptr).empty());
  EXPECT_EQ(third.stats().evaluations, edges);
  EXPECT_EQ(third.stats().deferred, 0u);
  EXPECT_TRUE(third.deferred_edges().empty());
  std::printf("%zu edges after %zu faces removed: %zu left deferred, queued uncosted again\n",
              edges, energy.repaired.mesh.face_count() - mesh.live_faces(), deferred.size());
}

}  // namespace
}  // namespace parapm
