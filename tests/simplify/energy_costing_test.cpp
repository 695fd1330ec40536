// The energy's two costings on real meshes (committed under tests/data): the queue key
// against the measured cost of the collapse to perform, and the thinned costing of stars
// with many points and curve samples against the costing of all of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "io/mesh_io.h"
#include "measure/surface_distance.h"
#include "mesh/repair.h"
#include "simplify/energy_priority.h"
#include "simplify/face_fold.h"
#include "simplify/point_projection.h"
#include "simplify/simplifier.h"
#include "simplify/simplify.h"
#include "test_support.h"
#include "util/chunked_loops.h"
#include "util/error.h"
#include "util/thread_team.h"

namespace parapm {
namespace {

struct Simplified {
  RepairedMesh repaired;
  std::unique_ptr<CollapseMesh> mesh;
  std::unique_ptr<EnergyPriority> energy;
};

// The mesh file at `path` simplified with the energy metric (options as given) down to `ratio`
// of its faces.
Simplified simplified_file(const std::string& path, const EnergyOptions& options, double ratio) {
  Simplified s;
  s.repaired = repair_mesh(read_mesh(path));
  const Mesh& mesh = s.repaired.mesh;
  const std::vector<uint8_t> locked = locked_vertices(s.repaired);
  s.mesh = std::make_unique<CollapseMesh>(mesh);
  s.energy = std::make_unique<EnergyPriority>(locked, options,
                                              WedgeAttributes{mesh.layout, mesh.wedge_values});
  Simplifier simplifier(*s.mesh, *s.energy, standard_constraints(locked));
  SimplifierLimits limits;
  limits.target_faces = size_t(double(mesh.face_count()) * ratio);
  simplifier.run(limits, {}, nullptr);
  return s;
}

// The same for `name` of tests/data.
Simplified simplified(const std::string& name, const EnergyOptions& options, double ratio) {
  return simplified_file(testing::test_data(name), options, ratio);
}

// Every live edge once.
template <typename Visit>
void for_each_edge(const CollapseMesh& mesh, Visit visit) {
  std::vector<VertexId> around;
  for (VertexId a = 0; a < mesh.vertex_capacity(); ++a) {
    if (!mesh.vertex_alive(a)) continue;
    mesh.neighbors(a, around);
    for (VertexId b : around)
      if (a < b) visit(a, b);
  }
}

// Whether collapsing {a, b} to v folds a face of the star (face_fold.h), as the face-geometry
// constraint judges it.
bool folds_a_face(const CollapseMesh& mesh, VertexId a, VertexId b, const Vec3& v) {
  for (const VertexId end : {a, b})
    for (const FaceId f : mesh.faces_of(end)) {
      const Triangle& t = mesh.face(f);
      if (corner_of(t, a) >= 0 && corner_of(t, b) >= 0) continue;  // removed by the collapse
      const std::array<Vec3, 3> before{mesh.position(t[0]), mesh.position(t[1]),
                                       mesh.position(t[2])};
      std::array<Vec3, 3> after = before;
      after[corner_of(t, end)] = v;
      if (face_folds(before[0], before[1], before[2], after[0], after[1], after[2])) return true;
    }
  return false;
}

// Whether the energy places the collapse of {a, b} (into c) and `rules` allow it.
bool legal_collapse(const CollapseMesh& mesh, EnergyPriority& energy,
                    const std::vector<std::unique_ptr<ConstraintModule>>& rules, VertexId a,
                    VertexId b, CollapseCandidate& c) {
  if (!energy.evaluate(mesh, a, b, c, Costing::kPerform)) return false;
  const EdgeFaces edge = mesh.edge_faces(c.vs, c.vt);
  for (const auto& rule : rules)
    if (!rule->allows(mesh, c, edge)) return false;
  return true;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// A key costs each start's solved position on the model it was solved on: each point stays
// at its barycentric coordinates on its face, a point of the new star, so the measured
// distance is never larger. A young star's key (an end still holds its own sample) starts
// from the two ends only, where the performed costing also tries the midpoint. Every star
// projected point by point (no moments) and E_scalar off: the key is never below the measured
// cost, unless every placement the key tried folds a face (the face-geometry constraint vetoes
// it; the collapse costed at the top then goes back with its measured cost); it is above where
// the midpoint's start wins (by design: such edges come later).
TEST(EnergyCosting, AQueueKeyIsAnUpperBoundOfTheMeasuredCost) {
  EnergyOptions options;
  options.max_points_per_evaluation = 1u << 30;
  for (const double ratio : {1.0, 0.5, 0.1}) {
    Simplified s = simplified("stratocaster-9k.ply", options, ratio);
    size_t edges = 0, above = 0, folded = 0;
    std::vector<double> gaps;
    for_each_edge(*s.mesh, [&](VertexId a, VertexId b) {
      CollapseCandidate key, perform;
      const bool queued = s.energy->evaluate(*s.mesh, a, b, key, Costing::kQueue);
      ASSERT_EQ(queued, s.energy->evaluate(*s.mesh, a, b, perform, Costing::kPerform));
      if (!queued) return;
      ++edges;
      ASSERT_EQ(key.vs, perform.vs);
      const double scale = std::abs(perform.cost) + 1e-30;
      if (folds_a_face(*s.mesh, a, b, key.position)) {
        folded += !folds_a_face(*s.mesh, a, b, perform.position);
        return;
      }
      ASSERT_GE(key.cost, perform.cost - 1e-9 * scale) << "edge " << a << " " << b;
      if (key.cost <= perform.cost) return;
      ++above;
      gaps.push_back((key.cost - perform.cost) / scale);
    });
    std::printf(
        "stratocaster-9k at %3.0f%%: %zu edges, key above the measured cost on %zu, by a "
        "median %.3g of the cost; placed where a face folds on %zu that the performed costing "
        "places legally\n",
        ratio * 100, edges, above, median(gaps), folded);
    // Measured: above on 77% / 82% / 79% of the edges at 100 / 50 / 10% (the midpoint's start
    // wins where no crease curve holds a vertex), by a median 0.19 / 0.031 / 0.0078 of the
    // cost; folded where the performed costing is legal on 4.2% / 1.0% / 0%.
    EXPECT_GT(edges, 1000u);
    EXPECT_LT(folded, edges / 10);
    EXPECT_LT(median(gaps), 3.0);
  }
}

// Late in the run a long seam's segments hold thousands of curve samples and a star hundreds
// of points: beyond max_sampled_points about one in k stands for k. On the textured bunny
// (UV seams everywhere, E_scalar on) at 15%, the thinned costs follow the full ones.
TEST(EnergyCosting, ThinnedSamplesCostLikeAllOfThem) {
  EnergyOptions options;
  options.attribute_weight = 0.01;
  Simplified s = simplified("pymeshlab-bunny-textured-10k.obj", options, 0.15);
  size_t edges = 0, differ = 0, same_order = 0, pairs = 0;
  std::vector<double> gaps;
  std::vector<std::pair<double, double>> costs;
  for_each_edge(*s.mesh, [&](VertexId a, VertexId b) {
    CollapseCandidate thinned, full;
    s.energy->set_max_sampled_points(64);
    const bool ok = s.energy->evaluate(*s.mesh, a, b, thinned, Costing::kPerform);
    s.energy->set_max_sampled_points(0);
    ASSERT_EQ(ok, s.energy->evaluate(*s.mesh, a, b, full, Costing::kPerform));
    if (!ok) return;
    ++edges;
    costs.push_back({thinned.cost, full.cost});
    if (thinned.cost == full.cost) return;
    ++differ;
    gaps.push_back(std::abs(thinned.cost - full.cost) / (std::abs(full.cost) + 1e-30));
  });
  // How often two edges, one of them thinned, compare the same way thinned and in full (the
  // queue's order).
  for (size_t i = 0; i + 1 < costs.size(); ++i) {
    if (costs[i].first == costs[i].second && costs[i + 1].first == costs[i + 1].second) continue;
    ++pairs;
    if ((costs[i].first < costs[i + 1].first) == (costs[i].second < costs[i + 1].second))
      ++same_order;
  }
  std::printf(
      "textured bunny at 15%%: %zu edges, %zu thinned: median gap %.3g of the cost, "
      "pairs with one of them in the same order %.1f%%\n",
      edges, differ, median(gaps), 100.0 * double(same_order) / double(pairs));
  EXPECT_GT(differ, 100u);  // the thinning is exercised
  EXPECT_LT(median(gaps), 0.05);
  EXPECT_GT(double(same_order), 0.95 * double(pairs));
}

// A performed collapse whose star holds more than max_points_per_reprojection points leaves
// its faces' points where they are (until a face's corners have moved by a quarter of its
// size): their stored distances lag behind the moved corners, and each face's drift keeps them
// upper bounds. With a cap of 32 on the stratocaster taken to 5%, every point's distance as the
// module states it is at least its true distance to its face, above it for many (the path is
// exercised), and the level stays near the build that re-projects every point: measured 1.28x
// its RMS (0.0129 against 0.0101; a cap of 32 is far below the default 1024, to exercise the
// path on a small mesh). The two builds' greedy paths part early and either may end the
// closer (DECISIONS.md, "The volume term at 64").
TEST(EnergyCosting, PointsLeftOnTheirFacesKeepUpperBoundsOfTheirDistances) {
  struct Outcome {
    size_t points = 0, above = 0;
    double true_sum = 0;
    double rms = 0;  // of the level against the input
  };
  auto run = [](uint32_t cap) {
    EnergyOptions options;
    options.max_points_per_reprojection = cap;
    Simplified s = simplified("stratocaster-9k.ply", options, 0.05);
    Outcome out;
    for (const EnergyPriority::PointState& p : s.energy->point_states()) {
      if (p.face == kNoId) continue;
      EXPECT_TRUE(s.mesh->face_alive(p.face));
      const Triangle& t = s.mesh->face(p.face);
      const double truth = project_on_triangle(p.position, s.mesh->position(t[0]),
                                               s.mesh->position(t[1]), s.mesh->position(t[2]))
                               .distance_sq;
      // (Rounding: the stored distances come from another formula than the check's.)
      EXPECT_GE(p.distance_sq, truth * (1 - 1e-6)) << "point on face " << p.face;
      ++out.points;
      out.true_sum += truth;
      if (p.distance_sq > truth * (1 + 1e-6) + 1e-30) ++out.above;
    }
    out.rms = surface_distance(s.repaired.mesh, testing::live_mesh(*s.mesh), 100000).rms;
    return out;
  };
  const Outcome kept = run(32), moved = run(0);
  std::printf(
      "stratocaster-9k at 5%%: %zu points on faces, %zu with a lagging bound; true squared "
      "distances %.4g (cap 32) against %.4g (every point re-projected); level RMS %.4g "
      "against %.4g\n",
      kept.points, kept.above, kept.true_sum, moved.true_sum, kept.rms, moved.rms);
  EXPECT_GT(kept.above, 100u);  // the path is exercised
  EXPECT_EQ(moved.above, 0u);
  EXPECT_LT(kept.rms, 1.4 * moved.rms);
}

// A copy of the live mesh whose module imports the master's state with the faces' drifts
// (export_with_drifts, set_drifts: the parallel build's final pass on a copy, live_pass.h)
// costs every edge as the master does; with a job's state, whose distances are the drifted
// bounds, some edges cost otherwise (the path is exercised). Each module read straight from the
// master (import_from) is the one its state makes. The stratocaster at 20% with a
// reprojection cap of 16, so that faces drift on a small mesh.
TEST(EnergyCosting, ACopyWithItsDriftsCostsAsTheMasterDoes) {
  const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data("stratocaster-9k.ply")));
  EnergyOptions options;
  options.max_points_per_reprojection = 16;
  options.reference_diagonal = bounding_box(repaired.mesh).diagonal();
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  CollapseMesh whole(repaired.mesh);
  EnergyPriority master(locked, options);  // (without attributes: the copy carries no wedges)
  {
    Simplifier simplifier(whole, master, standard_constraints(locked));
    SimplifierLimits limits;
    limits.target_faces = repaired.mesh.face_count() / 5;
    simplifier.run(limits, {}, nullptr);
  }
  // The live part, numbered in order, each fan in the whole mesh's order.
  std::vector<VertexId> vertex_of_copy, copy_of_vertex(whole.vertex_capacity(), kNoId);
  std::vector<FaceId> face_of_copy, copy_of_face(whole.face_capacity(), kNoId);
  Mesh part;
  for (VertexId v = 0; v < whole.vertex_capacity(); ++v)
    if (whole.vertex_alive(v)) {
      copy_of_vertex[v] = VertexId(vertex_of_copy.size());
      vertex_of_copy.push_back(v);
      part.positions.push_back(whole.position(v));
    }
  for (FaceId f = 0; f < whole.face_capacity(); ++f)
    if (whole.face_alive(f)) {
      copy_of_face[f] = FaceId(face_of_copy.size());
      face_of_copy.push_back(f);
      const Triangle& t = whole.face(f);
      part.faces.push_back({copy_of_vertex[t[0]], copy_of_vertex[t[1]], copy_of_vertex[t[2]]});
    }
  CollapseMesh copy(part);
  for (VertexId v = 0; v < vertex_of_copy.size(); ++v) {
    std::vector<FaceId> fan;
    for (FaceId f : whole.faces_of(vertex_of_copy[v])) fan.push_back(copy_of_face[f]);
    copy.order_faces_of(v, fan);
  }
  std::vector<uint8_t> copy_locked;
  for (VertexId g : vertex_of_copy) copy_locked.push_back(locked.empty() ? 0 : locked[g]);
  const std::vector<WedgeId> no_wedges;
  const IdMaps maps{&vertex_of_copy, &face_of_copy, &no_wedges};
  ChunkedLoops loops;
  std::vector<double> drifts;
  EnergyPriority with_drifts(copy_locked, options), with_bounds(copy_locked, options);
  with_drifts.import_local(copy, master.export_with_drifts(maps, loops, drifts));
  with_drifts.set_drifts(drifts);
  with_bounds.import_local(copy, master.export_local(maps));
  // The same two modules read straight from the master (in-process: no state in between).
  EnergyPriority direct_drifts(copy_locked, options), direct_bounds(copy_locked, options);
  direct_drifts.import_from(master, copy, maps, true, loops);
  direct_bounds.import_from(master, copy, maps, false, loops);
  const size_t drifted =
      size_t(std::count_if(drifts.begin(), drifts.end(), [](double d) { return d > 0; }));

  size_t edges = 0, same_with_drifts = 0, same_with_bounds = 0, same_direct = 0;
  for_each_edge(whole, [&](VertexId a, VertexId b) {
    CollapseCandidate m, d, u, dd, du;
    const bool placed = master.evaluate(whole, a, b, m, Costing::kQueue);
    const bool placed_d =
        with_drifts.evaluate(copy, copy_of_vertex[a], copy_of_vertex[b], d, Costing::kQueue);
    const bool placed_u =
        with_bounds.evaluate(copy, copy_of_vertex[a], copy_of_vertex[b], u, Costing::kQueue);
    ++edges;
    if (placed == placed_d && (!placed || m.cost == d.cost)) ++same_with_drifts;
    if (placed == placed_u && (!placed || m.cost == u.cost)) ++same_with_bounds;
    const bool placed_dd =
        direct_drifts.evaluate(copy, copy_of_vertex[a], copy_of_vertex[b], dd, Costing::kQueue);
    const bool placed_du =
        direct_bounds.evaluate(copy, copy_of_vertex[a], copy_of_vertex[b], du, Costing::kQueue);
    if (placed_dd == placed_d && (!placed_d || dd.cost == d.cost) && placed_du == placed_u &&
        (!placed_u || du.cost == u.cost))
      ++same_direct;
  });
  std::printf(
      "stratocaster-9k at 20%%, cap 16: %zu of %zu faces drifted; of %zu edges, %zu cost as the "
      "master's with the drifts, %zu with the bounds\n",
      drifted, drifts.size(), edges, same_with_drifts, same_with_bounds);
  EXPECT_GT(drifted, 100u);
  EXPECT_EQ(same_with_drifts, edges);
  EXPECT_LT(same_with_bounds, edges);
  EXPECT_EQ(same_direct, edges);
  // Point by point, the same ids, places, distances, faces and parked samples.
  auto same_points = [](const EnergyPriority& x, const EnergyPriority& y) {
    const auto a = x.point_states(), b = y.point_states();
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
      if (a[i].position != b[i].position || a[i].distance_sq != b[i].distance_sq ||
          a[i].face != b[i].face || a[i].parked != b[i].parked)
        return false;
    return true;
  };
  EXPECT_TRUE(same_points(direct_drifts, with_drifts));
  EXPECT_TRUE(same_points(direct_bounds, with_bounds));
  std::vector<double> short_list(drifts.size() - 1, 0.0);
  EXPECT_THROW(with_drifts.set_drifts(short_list), Error);
  drifts[0] = -1;
  EXPECT_THROW(with_drifts.set_drifts(drifts), Error);
}

// Hoppe's spring constants with one point per vertex let a young star's springs outweigh its
// points' distances, and collapses go by edge length: the default scale (EnergyOptions::
// spring_scale) gives the scanned vessel an RMS distance to its input at 10% no higher than
// Hoppe's own values, and about as low at 2% (measured: 0.994 and 1.008 of it; at 2% the two are
// within the mesh numbering's noise). With the star's planes the springs matter less than they
// did; the choice, on nine meshes: docs/decisions/notebook-2026-11.md, "E_spring's weight".
TEST(EnergyCosting, ScaledSpringsKeepTheSurfaceCloserThanHoppesValues) {
  const Mesh input = repair_mesh(read_mesh(testing::test_data("gmsh-aneurysm-20k.stl.gz"))).mesh;
  for (const double ratio : {0.1, 0.02}) {
    EnergyOptions hoppe;
    hoppe.spring_scale = 1;
    const Simplified scaled = simplified("gmsh-aneurysm-20k.stl.gz", EnergyOptions{}, ratio);
    const Simplified original = simplified("gmsh-aneurysm-20k.stl.gz", hoppe, ratio);
    const SurfaceDistance a = surface_distance(input, testing::live_mesh(*scaled.mesh), 100000);
    const SurfaceDistance b = surface_distance(input, testing::live_mesh(*original.mesh), 100000);
    std::printf(
        "gmsh-aneurysm-20k at %2.0f%%: RMS %.3g (scale %.2g) against %.3g (Hoppe's), ratio %.3f\n",
        ratio * 100, a.rms, EnergyOptions{}.spring_scale, b.rms, a.rms / b.rms);
    EXPECT_LT(a.rms, (ratio > 0.05 ? 1.0 : 1.05) * b.rms) << "at " << ratio;
  }
}

// The star's planes and volume preservation (energy_priority.h) measure the surface between
// the points, which one point per vertex does not see: with them a scanned vessel and a CAD
// part (flat and cylindrical patches) come out closer to their inputs at 50% and 10% (measured:
// RMS 0.49x / 0.30x at 50%, 0.87x / 0.77x at 10%; on 18 meshes: docs/decisions/notebook-2026-11.md,
// "The star's planes and its volume").
TEST(EnergyCosting, StarPlanesAndVolumeKeepTheSurfaceCloser) {
  for (const char* name : {"gmsh-aneurysm-20k.stl.gz", "cad-cycloidal-43k.ply"}) {
    const Mesh input = repair_mesh(read_mesh(testing::test_data(name))).mesh;
    for (const double ratio : {0.5, 0.1}) {
      EnergyOptions without;
      without.star_planes_weight = 0;
      without.volume_weight = 0;
      const Simplified with_terms = simplified(name, EnergyOptions{}, ratio);
      const Simplified points_only = simplified(name, without, ratio);
      const SurfaceDistance a =
          surface_distance(input, testing::live_mesh(*with_terms.mesh), 100000);
      const SurfaceDistance b =
          surface_distance(input, testing::live_mesh(*points_only.mesh), 100000);
      std::printf("%s at %2.0f%%: RMS %.3g with the star's terms, %.3g without, ratio %.3f\n", name,
                  ratio * 100, a.rms, b.rms, a.rms / b.rms);
      EXPECT_LT(a.rms, (ratio > 0.3 ? 0.7 : 1.0) * b.rms) << name << " at " << ratio;
    }
  }
}

// With creases on (at 60 degrees; off by default), a scan's noise makes hundreds of creases of
// one to three edges above the crease angle; kept as curves, each holds its vertices until its
// collapses are worth the price of changing the curves' topology. Dropped
// (SharpEdgeOptions::min_crease_edges), they hold nothing: the levels are closer on the textured
// bunny at 10% (0.98x the RMS), and on the nefertiti scan at 2% when ../shared/meshes is present
// (0.70x).
TEST(EnergyCosting, NoiseCreasesDoNotHoldTheCoarseLevels) {
  struct Case {
    std::string path;
    double ratio, factor;
  };
  std::vector<Case> cases = {{testing::test_data("pymeshlab-bunny-textured-10k.obj"), 0.1, 1.0}};
  const auto nefertiti = testing::shared_meshes_dir() / "nefertiti-100k.obj";
  if (std::filesystem::exists(nefertiti)) cases.push_back({nefertiti.string(), 0.02, 0.8});
  for (const Case& c : cases) {
    const Mesh input = repair_mesh(read_mesh(c.path)).mesh;
    EnergyOptions creases;
    creases.sharp.crease_angle_degrees = 60;
    EnergyOptions every_crease = creases;
    every_crease.sharp.min_crease_edges = 1;
    const Simplified dropped = simplified_file(c.path, creases, c.ratio);
    const Simplified kept = simplified_file(c.path, every_crease, c.ratio);
    const SurfaceDistance a = surface_distance(input, testing::live_mesh(*dropped.mesh), 100000);
    const SurfaceDistance b = surface_distance(input, testing::live_mesh(*kept.mesh), 100000);
    std::printf("%s at %.0f%%: RMS %.3g with short creases dropped, %.3g with every crease\n",
                std::filesystem::path(c.path).filename().c_str(), c.ratio * 100, a.rms, b.rms);
    EXPECT_LT(a.rms, c.factor * b.rms) << c.path;
  }
}

// Checks, as the last constraint (after the standard ones, so on every candidate the
// simplifier is about to perform or to requeue), that the candidate is what a fresh
// performed costing of the present mesh gives.
class FreshCosting : public ConstraintModule {
 public:
  explicit FreshCosting(PriorityModule& priority) : priority_(priority) {}
  std::string name() const override { return "fresh costing"; }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces&) const override {
    CollapseCandidate fresh;
    // As the simplifier asks: the edge's ends in id order.
    const bool placed = priority_.evaluate(mesh, std::min(c.vs, c.vt), std::max(c.vs, c.vt), fresh,
                                           Costing::kPerform);
    ++checked;
    if (!placed || fresh.vs != c.vs || fresh.cost != c.cost || fresh.position != c.position)
      ++differ;
    return true;
  }
  mutable uint64_t checked = 0, differ = 0;

 private:
  PriorityModule& priority_;
};

// The simplifier puts back an edge whose cost grew past the next key, and takes its costing
// out again with it when no collapse has changed the edge's star in between: every candidate
// it acts on is still the fresh costing of the mesh as it is.
TEST(EnergyCosting, ARequeuedEdgeKeepsItsCostingWhileItsStarStays) {
  for (const char* name : {"stratocaster-9k.ply", "pymeshlab-bunny-textured-10k.obj"}) {
    const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data(name)));
    SimplifyOptions options;
    options.metric = "energy";
    const std::vector<uint8_t> locked = locked_vertices(repaired);
    CollapseMesh mesh(repaired.mesh);
    std::unique_ptr<PriorityModule> priority = make_priority_module(options, repaired.mesh, locked);
    auto constraints = standard_constraints(locked);
    auto check = std::make_unique<FreshCosting>(*priority);
    const FreshCosting& checker = *check;
    constraints.push_back(std::move(check));
    Simplifier simplifier(mesh, *priority, std::move(constraints));
    simplifier.run({mesh.live_faces() / 20}, {}, nullptr);
    const SimplifierStats& stats = simplifier.stats();
    EXPECT_GT(stats.requeued, 50u) << name;
    EXPECT_GT(stats.requeue_reused, 10u) << name;
    EXPECT_EQ(checker.differ, 0u) << name << ": of " << checker.checked;
    std::printf("%-36s %llu collapses, %llu requeued, %llu taken out again unchanged\n", name,
                (unsigned long long)stats.collapses, (unsigned long long)stats.requeued,
                (unsigned long long)stats.requeue_reused);
  }
}

// The energy's initialisation parts (its sharp curves, its points and the rest) run side by side
// in the parallel build; in any order and on other threads, they give the module initialize()
// gives: the same collapses, bit for bit, on meshes with creases and with attribute seams.
// release_caches (the parallel build's master while its jobs run) changes no costing: a module
// whose caches were released, then followed through more collapses, costs every edge as one
// that kept them, bit for bit.
TEST(EnergyCosting, ReleasedCachesChangeNoCosting) {
  const RepairedMesh repaired =
      repair_mesh(read_mesh(testing::test_data("cad-featuretype-3k.stl")));
  const Mesh& mesh = repaired.mesh;
  const std::vector<uint8_t> locked = locked_vertices(repaired);
  CollapseMesh kept_mesh(mesh), released_mesh(mesh);
  EnergyPriority kept(locked, EnergyOptions{}), released(locked, EnergyOptions{});
  Simplifier kept_run(kept_mesh, kept, standard_constraints(locked));
  Simplifier released_run(released_mesh, released, standard_constraints(locked));
  SimplifierLimits limits;
  limits.target_faces = mesh.face_count() / 2;
  kept_run.run(limits, {}, nullptr);
  released_run.run(limits, {}, nullptr);
  // Both modules have costed edges and filled their caches; one forgets them, and both follow
  // the same further collapses (collapsed() moves corners and points with the caches released).
  released.release_caches();
  auto rules = standard_constraints(locked);
  for (const auto& rule : rules) rule->initialize(kept_mesh);
  size_t collapses = 0;
  for_each_edge(kept_mesh, [&](VertexId a, VertexId b) {
    if (collapses >= 20 || !kept_mesh.vertex_alive(a) || !kept_mesh.vertex_alive(b)) return;
    CollapseCandidate c;
    if (!legal_collapse(kept_mesh, kept, rules, a, b, c)) return;
    std::vector<double> errors;  // the records' error bounds, refined by collapsed()
    for (const auto& pair : {std::pair{&kept_mesh, &kept}, std::pair{&released_mesh, &released}}) {
      CollapseCandidate done = c;
      done.vs_before = pair.first->position(c.vs);
      const EdgeFaces faces = pair.first->edge_faces(c.vs, c.vt);
      pair.first->collapse(c.vs, c.vt, c.position, faces);
      pair.second->collapsed(*pair.first, done, faces);
      errors.push_back(done.error);
    }
    EXPECT_EQ(errors[0], errors[1]);
    for (const auto& rule : rules) rule->collapsed(kept_mesh, c);
    if (collapses++ == 10) released.release_caches();
  });
  ASSERT_GT(collapses, 10u);
  size_t compared = 0;
  for_each_edge(kept_mesh, [&](VertexId a, VertexId b) {
    for (Costing costing : {Costing::kQueue, Costing::kPerform}) {
      CollapseCandidate x, y;
      const bool placed = kept.evaluate(kept_mesh, a, b, x, costing);
      ASSERT_EQ(released.evaluate(released_mesh, a, b, y, costing), placed);
      if (!placed) continue;
      EXPECT_EQ(x.vs, y.vs);
      EXPECT_EQ(x.position, y.position);
      EXPECT_EQ(x.cost, y.cost) << a << "-" << b;
      ++compared;
    }
  });
  EXPECT_GT(compared, 1000u);
}

// After a collapse that ran its projections on the team, the edges handed over together
// (evaluate_each: a collapse's ring and its neighbours') are costed side by side, each on a
// view of the module's evaluator: the answers, and the costings counted, are those of costing
// them one after the other. Late in the simplification (stars costed on their faces' point
// moments, read from the shared caches) and on a mesh with sharp curves (each view gathers its
// own curve samples).
TEST(EnergyPriority, EdgesCostedTogetherOnTheTeamCostAsOneAfterAnother) {
  for (const double ratio : {0.5, 0.05}) {
    Simplified s = simplified("cad-featuretype-3k.stl", EnergyOptions{}, ratio);
    CollapseMesh& mesh = *s.mesh;
    EnergyPriority& energy = *s.energy;
    ThreadTeam team(4, 4, 1);
    energy.use_team(&team);
    const std::vector<uint8_t> locked = locked_vertices(s.repaired);
    auto rules = standard_constraints(locked);
    for (const auto& rule : rules) rule->initialize(mesh);
    size_t batches = 0, compared = 0;
    for_each_edge(mesh, [&](VertexId a, VertexId b) {
      if (batches >= 8 || !mesh.vertex_alive(a) || !mesh.vertex_alive(b)) return;
      CollapseCandidate c;
      if (!legal_collapse(mesh, energy, rules, a, b, c)) return;
      const EdgeFaces edge = mesh.edge_faces(c.vs, c.vt);
      c.vs_before = mesh.position(c.vs);
      mesh.collapse(c.vs, c.vt, c.position, edge);
      energy.collapsed(mesh, c, edge);
      for (const auto& rule : rules) rule->collapsed(mesh, c);
      // The edges around vs and around its neighbours.
      std::vector<EdgeCosting> edges;
      std::vector<VertexId> ring, around;
      mesh.neighbors(c.vs, ring);
      for (const VertexId n : ring) {
        edges.push_back({std::min(c.vs, n), std::max(c.vs, n), false, {}});
        mesh.neighbors(n, around);
        for (const VertexId m : around)
          if (m != c.vs && n < m) edges.push_back({n, m, false, {}});
      }
      ASSERT_GE(edges.size(), 2u);
      for (const Costing costing : {Costing::kQueue, Costing::kPerform}) {
        const double team_seconds = team.seconds();
        const uint64_t costings = energy.costings();
        energy.evaluate_each(mesh, edges, costing);
        EXPECT_GT(team.seconds(), team_seconds) << "not costed on the team";
        EXPECT_EQ(energy.costings(), costings + edges.size());
        for (const EdgeCosting& e : edges) {
          CollapseCandidate alone;
          ASSERT_EQ(energy.evaluate(mesh, e.a, e.b, alone, costing), e.placed) << e.a << "-" << e.b;
          if (!e.placed) continue;
          EXPECT_EQ(alone.vs, e.candidate.vs);
          EXPECT_EQ(alone.position, e.candidate.position);
          EXPECT_EQ(alone.cost, e.candidate.cost) << ratio << ": " << e.a << "-" << e.b;
          EXPECT_EQ(alone.error, e.candidate.error);
          ++compared;
        }
      }
      ++batches;
    });
    EXPECT_EQ(batches, 8u) << ratio;
    EXPECT_GT(compared, 200u) << ratio;
    energy.use_team(nullptr);
  }
}

// A first queue's many edges (a band pass's, Simplifier::queue_edges_around) go to the team
// before any collapse woke it, and cost as one after another; a few edges stay off it.
TEST(EnergyPriority, ManyEdgesAreCostedOnTheTeamBeforeACollapseWakesIt) {
  Simplified s = simplified("cad-featuretype-3k.stl", EnergyOptions{}, 0.2);
  CollapseMesh& mesh = *s.mesh;
  EnergyPriority& energy = *s.energy;
  ThreadTeam team(4, 4, 1);
  energy.use_team(&team);
  std::vector<EdgeCosting> edges;
  for_each_edge(mesh, [&](VertexId a, VertexId b) {
    if (mesh.vertex_alive(a) && mesh.vertex_alive(b) && edges.size() < 200)
      edges.push_back({a, b, false, {}});
  });
  ASSERT_GE(edges.size(), EnergyPriority::kEdgesWakingTheTeam);
  std::vector<EdgeCosting> few(edges.begin(), edges.begin() + 8);
  double team_seconds = team.seconds();
  energy.evaluate_each(mesh, few, Costing::kQueue);
  EXPECT_EQ(team.seconds(), team_seconds) << "a few edges woke the team";
  energy.evaluate_each(mesh, edges, Costing::kQueue);
  EXPECT_GT(team.seconds(), team_seconds) << "many edges not costed on the team";
  size_t placed = 0;
  for (const EdgeCosting& e : edges) {
    CollapseCandidate alone;
    ASSERT_EQ(energy.evaluate(mesh, e.a, e.b, alone, Costing::kQueue), e.placed);
    if (!e.placed) continue;
    EXPECT_EQ(alone.position, e.candidate.position);
    EXPECT_EQ(alone.cost, e.candidate.cost) << e.a << "-" << e.b;
    ++placed;
  }
  EXPECT_GT(placed, 100u);
  energy.use_team(nullptr);
}

TEST(EnergyPriority, InitializationInChunksSideBySideEqualsInitialize) {
  // Keeps the state the chunks made: the simplifier would initialise the module again.
  class Initialized : public PriorityWrapper {
   public:
    using PriorityWrapper::PriorityWrapper;
    void initialize(const CollapseMesh&) override {}
  };
  for (const char* name : {"cad-featuretype-3k.stl", "pymeshlab-colored-airplane-11k.ply"}) {
    const RepairedMesh repaired = repair_mesh(read_mesh(testing::test_data(name)));
    SimplifyOptions options;
    options.metric = "energy";
    const std::vector<uint8_t> locked = locked_vertices(repaired);
    auto run = [&](bool in_chunks) {
      // Seven chunks of at least 64 items, on three threads.
      ChunkedLoops loops(7, 3, 64);
      CollapseMesh mesh =
          in_chunks ? CollapseMesh(repaired.mesh, loops) : CollapseMesh(repaired.mesh);
      std::unique_ptr<PriorityModule> energy = make_priority_module(options, repaired.mesh, locked);
      std::unique_ptr<PriorityModule> priority;
      if (in_chunks) {
        energy->initialize_in_chunks(mesh, loops);
        EXPECT_LE(loops.critical_seconds(), loops.seconds()) << name;
        priority = std::make_unique<Initialized>(*energy);
      }
      Simplifier simplifier(mesh, priority ? *priority : *energy, standard_constraints(locked));
      return simplifier.run({mesh.live_faces() / 10}, {}, nullptr);
    };
    const std::vector<CollapseRecord> whole = run(false), parts = run(true);
    ASSERT_EQ(whole.size(), parts.size()) << name;
    EXPECT_GT(whole.size(), repaired.mesh.vertex_count() / 2) << name;
    for (size_t i = 0; i < whole.size(); ++i) {
      ASSERT_EQ(whole[i].vs, parts[i].vs) << name << " collapse " << i;
      ASSERT_EQ(whole[i].vt, parts[i].vt) << name << " collapse " << i;
      ASSERT_EQ(whole[i].position, parts[i].position) << name << " collapse " << i;
      ASSERT_EQ(whole[i].cost, parts[i].cost) << name << " collapse " << i;
      ASSERT_EQ(whole[i].changed_values, parts[i].changed_values) << name << " collapse " << i;
    }
  }
}

}  // namespace
}  // namespace parapm
