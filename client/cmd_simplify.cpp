// parapm simplify IN -o OUT.pm: read, repair, build the Progressive Mesh (sequentially, or
// with --parallel P subsets on a thread pool), write it.
#include <chrono>
#include <cstdio>
#include <filesystem>

#include <optional>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "parallel/parallel_build.h"
#include "pm/pm_file.h"
#include "simplify/simplify.h"
#include "util/memory.h"

namespace parapm::cli {
namespace {

struct SimplifyArgs {
  std::string input;
  std::string output;
  uint64_t faces = 0;
  double ratio = 0;
  std::string metric = "quadric";
  std::string quadric_placement = quadric_placements().front();
  double samples_per_face = SimplifyOptions{}.samples_per_face;
  double crease_angle = 180;
  double attribute_weight = 0.01;
  EnergyTuning energy;
  uint64_t seed = 1;
  bool keep_order = false;
  bool free_copies = false;
  bool keep_components = false;
  uint32_t parallel = 1;  // subsets p; 1: the sequential build
  unsigned threads = 0;   // 0: min(p, hardware threads)
  uint32_t rounds = ParallelOptions{}.rounds;
  double handover = ParallelOptions{}.handover_ratio;
  double border_excess = ParallelOptions{}.border_excess;
  uint64_t extra_round_faces = ParallelOptions{}.extra_round_subset_faces;
  std::optional<uint64_t> min_subset_faces;  // unset: by the metric (subset_faces_by_metric)
  bool no_carry_keys = false;
  bool no_carry_deferred = false;
  bool no_band_pass = false;
  bool no_deferred_recosting = false;
  bool json = false;
};

nlohmann::json parallel_json(const ParallelStats& stats) {
  nlohmann::json rounds = nlohmann::json::array();
  for (const RoundStats& r : stats.round_stats) {
    nlohmann::json subsets = nlohmann::json::array();
    for (const SubsetTiming& s : r.subsets)
      subsets.push_back({{"subset", s.subset},
                         {"faces", s.faces},
                         {"owned_faces", s.owned_faces},
                         {"collapses", s.collapses},
                         {"wall_seconds", s.wall_seconds},
                         {"cpu_seconds", s.cpu_seconds},
                         {"stop_reason", s.stop_reason}});
    rounds.push_back({{"round", r.round},
                      {"faces_before", r.faces_before},
                      {"goal_faces", r.goal_faces},
                      {"border_faces", r.border_faces},
                      {"border_limited", r.border_limited},
                      {"asked_faces", r.asked_faces},
                      {"faces_after", r.faces_after},
                      {"partition_seconds", r.partition_seconds},
                      {"append_seconds", r.append_seconds},
                      {"partition_foreseen", r.partition_foreseen},
                      {"partition_overlap_seconds", r.partition_overlap_seconds},
                      {"extract_seconds", r.extract_seconds},
                      {"share_seconds", r.share_seconds},
                      {"slowest_extract_cpu_seconds", r.slowest_extract_cpu_seconds},
                      {"extract_critical_seconds", r.extract_critical_seconds},
                      {"subsets_seconds", r.subsets_seconds},
                      {"merge_seconds", r.merge_seconds},
                      {"merge_overlap_seconds", r.merge_overlap_seconds},
                      {"slowest_subset_cpu_seconds", r.slowest_subset_cpu_seconds},
                      {"water_level", r.water_level},
                      {"keys_carried", r.keys_carried},
                      {"deferred_carried", r.deferred_carried},
                      {"keys_reused", r.keys_reused},
                      {"band_pass_collapses", r.band_pass_collapses},
                      {"band_pass_seconds", r.band_pass_seconds},
                      {"append_beyond_band_seconds", r.append_beyond_band_seconds},
                      {"critical_seconds", round_critical_seconds(r)},
                      {"subsets", subsets}});
  }
  return {{"p", stats.subsets},
          {"rounds", stats.rounds},
          {"threads", stats.threads},
          {"round_stats", rounds},
          {"setup_seconds", stats.setup_seconds},
          {"final_pass_collapses", stats.final_pass_collapses},
          {"final_pass_on_live_copy", stats.final_pass_on_live_copy},
          {"final_pass_seconds", stats.final_pass_seconds},
          {"final_work_seconds", stats.final_work_seconds},
          {"final_append_seconds", stats.final_append_seconds},
          {"pm_build_seconds", stats.pm_build_seconds},
          {"cpu_seconds", stats.cpu_seconds},
          {"costings", stats.costings},
          {"critical_path_seconds", stats.critical_path_seconds}};
}

int run_simplify(const SimplifyArgs& args) {
  RepairOptions repair_options;
  repair_options.keep_unreferenced = args.keep_order;  // the input's numbering needs them
  // A parallel build reads and repairs in p chunks on its threads too.
  ChunkedLoops loops(args.parallel, args.threads);
  if (args.parallel > 1) {
    repair_options.loops = &loops;
    map_large_blocks_alone();
  }
  LoadedMesh loaded = load_and_repair(args.input, repair_options);

  SimplifyOptions options;
  options.target_faces = args.faces;
  options.target_ratio = args.ratio;
  options.metric = args.metric;
  options.free_placement_above_faces = free_placement_above_faces_of(args.quadric_placement);
  options.samples_per_face = args.samples_per_face;
  options.crease_angle_degrees = args.crease_angle;
  options.attribute_weight = args.attribute_weight;
  options.energy = args.energy;
  options.seed = args.seed;
  options.keep_order = args.keep_order;
  options.free_copies = args.free_copies;
  options.keep_components = args.keep_components;
  options.defer_recosting = !args.no_deferred_recosting;
  SimplifyStats stats;
  ParallelStats parallel_stats;
  ProgressBar bar("simplify");
  ProgressiveMesh pm;
  if (args.parallel > 1) {
    ParallelOptions parallel;
    parallel.subsets = args.parallel;
    parallel.threads = args.threads;
    parallel.rounds = args.rounds;
    parallel.handover_ratio = args.handover;
    parallel.border_excess = args.border_excess;
    parallel.extra_round_subset_faces = args.extra_round_faces;
    if (args.min_subset_faces) parallel.min_subset_faces = *args.min_subset_faces;
    parallel.carry_keys = !args.no_carry_keys;
    parallel.carry_deferred = !args.no_carry_deferred;
    parallel.band_pass = !args.no_band_pass;
    pm = build_progressive_mesh_parallel(loaded.repaired, options, parallel, &parallel_stats,
                                         bar.callback(), nullptr);
    stats.collapses = parallel_stats.collapses;
    stats.stop_reason = parallel_stats.stop_reason;
    stats.seconds = parallel_stats.seconds;
    stats.costings = parallel_stats.costings;
    stats.cpu_seconds = parallel_stats.cpu_seconds;
  } else {
    pm = build_progressive_mesh(loaded.repaired, options, &stats, bar.callback(), nullptr);
  }
  bar.finish();

  const auto write_start = std::chrono::steady_clock::now();
  const LoopClock write_clock(loops);
  write_pm_file(pm, args.output, loops);
  const double write_seconds = seconds_since(write_start);
  const double write_critical_seconds = write_clock.critical_seconds();
  const uint64_t pm_bytes = std::filesystem::file_size(args.output);
  const uint64_t ply_bytes = binary_ply_size(loaded.repaired.mesh);
  const uint64_t peak = peak_memory_bytes();
  spdlog::info("simplified {}: {} -> {} faces, {} vertex splits, {:.3f} s ({}); wrote {}",
               args.input, loaded.repaired.mesh.face_count(), pm.base.face_count(),
               pm.splits.size(), stats.seconds, stats.stop_reason, args.output);

  if (args.json) {
    nlohmann::json out = {{"input", args.input},
                          {"output", args.output},
                          {"in_vertices", loaded.input_vertices},
                          {"in_faces", loaded.input_faces},
                          {"repaired_vertices", loaded.repaired.mesh.vertex_count()},
                          {"repaired_faces", loaded.repaired.mesh.face_count()},
                          {"base_vertices", pm.base.vertex_count()},
                          {"base_faces", pm.base.face_count()},
                          {"vsplits", pm.splits.size()},
                          {"seconds", stats.seconds},
                          {"read_seconds", loaded.read_seconds},
                          {"repair_seconds", loaded.repair_seconds},
                          {"read_critical_seconds", loaded.read_critical_seconds},
                          {"repair_critical_seconds", loaded.repair_critical_seconds},
                          {"write_seconds", write_seconds},
                          {"write_critical_seconds", write_critical_seconds},
                          {"metric", pm.info.metric},
                          {"stop_reason", stats.stop_reason},
                          {"costings", stats.costings},
                          {"cpu_seconds", stats.cpu_seconds},
                          {"pm_bytes", pm_bytes},
                          {"binary_ply_bytes", ply_bytes},
                          {"peak_memory_bytes", peak},
                          {"repairs", repair_report_json(loaded.repaired.report)}};
    if (args.parallel > 1) out["parallel"] = parallel_json(parallel_stats);
    print_json(out);
  } else {
    std::printf("input      %s: %llu vertices, %llu faces\n", args.input.c_str(),
                (unsigned long long)loaded.input_vertices, (unsigned long long)loaded.input_faces);
    std::printf("base mesh  %zu vertices, %zu faces\n", pm.base.vertex_count(),
                pm.base.face_count());
    std::printf("vsplits    %zu (%s)\n", pm.splits.size(), stats.stop_reason.c_str());
    std::printf("time       %.3f s simplification, %.3f s read, %.3f s repair\n", stats.seconds,
                loaded.read_seconds, loaded.repair_seconds);
    if (args.parallel > 1) {
      double subsets = 0, merge = 0;
      for (const RoundStats& r : parallel_stats.round_stats) {
        subsets += r.subsets_seconds;
        merge += r.merge_seconds;
      }
      std::printf(
          "parallel   p=%u, %u rounds on %u threads: subsets %.3f s, merge %.3f s, final pass "
          "%.3f s (%llu collapses), %.3f s CPU in all, critical path %.3f s\n",
          parallel_stats.subsets, parallel_stats.rounds, parallel_stats.threads, subsets, merge,
          parallel_stats.final_pass_seconds,
          (unsigned long long)parallel_stats.final_pass_collapses, parallel_stats.cpu_seconds,
          parallel_stats.critical_path_seconds);
    }
    std::printf("size       %llu bytes .pm, %llu bytes binary PLY (%.2fx)\n",
                (unsigned long long)pm_bytes, (unsigned long long)ply_bytes,
                ply_bytes ? double(pm_bytes) / double(ply_bytes) : 0.0);
  }
  return 0;
}

}  // namespace

void add_simplify_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SimplifyArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simplify", "Build a Progressive Mesh from a mesh file (OBJ, PLY, OFF, STL, optionally .gz)");
  cmd->add_option("input", args->input, "Input mesh")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "Output .pm file")->required();
  auto* faces = cmd->add_option("--faces", args->faces,
                                "Base mesh size in faces (default: simplify as far as "
                                "collapses stay legal)");
  cmd->add_option("--ratio", args->ratio, "Base mesh size as a fraction of the input faces")
      ->check(CLI::Range(0.0, 1.0))
      ->excludes(faces);
  cmd->add_option("--metric", args->metric,
                  "Priority metric: quadric (Garland-Heckbert quadrics, fastest) or energy "
                  "(Hoppe's energy: distances of points sampled on the input)")
      ->check(CLI::IsMember({"quadric", "energy"}))
      ->capture_default_str();
  cmd->add_option("--quadric-placement", args->quadric_placement,
                  "Quadric metric: where a collapse puts its vertex. auto: at the summed "
                  "quadric's optimum while more than a fifth of the input's faces (and 2000) "
                  "are live, below that where the star keeps its volume and border; "
                  "constrained: volume and border kept at every level (the finest levels "
                  "nearest the input, the build slower); free: the optimum at every level "
                  "(the fastest build; coarse levels shrink and their borders drift)")
      ->check(CLI::IsMember(quadric_placements()))
      ->capture_default_str();
  cmd->add_option("--samples-per-face", args->samples_per_face,
                  "Energy metric: extra points drawn on the input per face, by area, beyond "
                  "one per vertex: they measure the surface between the vertices (0: the "
                  "vertices only, about a fifth faster, coarser levels less faithful)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--crease-angle", args->crease_angle,
                  "Energy metric: degrees between face normals above which an edge is a crease, "
                  "kept as a curve like boundaries and attribute seams (180, the default: none; "
                  "the star's planes keep creases without curves, which hold coarse levels "
                  "back); a crease of fewer than --crease-min-edges edges and shorter than "
                  "--crease-min-length is taken for a scan's noise and not kept")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  cmd->add_option("--crease-min-edges", args->energy.min_crease_edges,
                  "Energy metric: a crease of fewer edges than this (and shorter than "
                  "--crease-min-length) is noise, not kept (1: every crease is kept)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--crease-min-length", args->energy.crease_min_length,
                  "Energy metric: a crease shorter than this, in bounding-box diagonals (and of "
                  "fewer than --crease-min-edges edges), is noise, not kept (0: by edges alone)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_option("--star-planes-weight", args->energy.star_planes_weight,
                  "Energy metric: weight of the collapse's distance to the planes of its star "
                  "(Lindstrom-Turk's term, as points this many times as dense as the star's "
                  "would measure it) against the sample points' distances (0: off)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--volume-weight", args->energy.volume_weight,
                  "Energy metric: weight of the enclosed volume's change (Lindstrom-Turk's "
                  "term, as a mean displacement of the star's points) (0: off)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--spring-scale", args->energy.spring_scale,
                  "Energy metric: E_spring's kappa is Hoppe's schedule (from the points per "
                  "face around the edge) times this (0: no springs)")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--attribute-weight", args->attribute_weight,
                  "Energy metric: weight of colours, normals and texture coordinates against "
                  "geometry (an attribute difference of 1 costs like this fraction of the "
                  "bounding-box diagonal); 0: wedges keep their input values at every level")
      ->check(CLI::Range(0.0, 1000.0))
      ->capture_default_str();
  cmd->add_option("--seed", args->seed,
                  "Seed of the randomised steps (the energy's extra points): same input, "
                  "options and seed, same .pm")
      ->capture_default_str();
  cmd->add_flag("--keep-order", args->keep_order,
                "Store the input's vertex and face order, and keep unreferenced vertices");
  cmd->add_flag("--free-copies", args->free_copies,
                "Let the copies the repair makes of a non-manifold input vertex (one per sheet "
                "meeting there) simplify like any vertex: coarser levels reach further and stay "
                "closer to the input, but the sheets part at coarse levels (cracks, far wider "
                "than the level's distance error: docs/decisions/notebook-2026-11.md). Default: "
                "the copies move and leave only together, so the sheets stay joined (but for "
                "a part lying on another with no vertex of its own, such as a back face laid "
                "on a surface, which simplifies freely and may vanish); where that cannot be "
                "done, they are most of what remains at coarse levels of a mesh with many of "
                "them");
  cmd->add_flag("--keep-components", args->keep_components,
                "Keep at least one triangle of every connected component at every level. "
                "Default: an open component's last triangle collapses away when its cost comes, "
                "so small separate parts vanish at coarse levels (a vertex split brings each "
                "back) and a scene of many parts simplifies below one triangle per part; the "
                "largest component, closed ones (a tetrahedron at least) and those with a "
                "vertex where another component has one keep theirs");
  cmd->add_option("--parallel", args->parallel,
                  "Build with P subsets simplified in parallel (Langis 1999): --rounds rounds, "
                  "each partitioning the current mesh anew and simplifying the subsets in "
                  "parallel (merged by cost), down to the handover; then a sequential final "
                  "pass over the last borders to the target. 1: the sequential build")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_option("--threads", args->threads,
                  "With --parallel: threads of the pool, which also read, repair and set up in "
                  "P chunks, and share the energy's last collapses (0: min(P, hardware "
                  "threads)); the .pm does not depend on it")
      ->capture_default_str();
  cmd->add_option("--rounds", args->rounds,
                  "With --parallel: parallel rounds, each on a new partition (the borders "
                  "move); they take the mesh geometrically down to the handover (0: by P, 2 at "
                  "P = 2, 3 above); rounds shortened by --border-excess come on top")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  cmd->add_option("--handover-ratio", args->handover,
                  "With --parallel: the rounds simplify the mesh down to this fraction of the "
                  "input faces (or the target if larger); the sequential final pass does the "
                  "rest")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--border-excess", args->border_excess,
                  "With --parallel: a round ends where the faces along its cut, which it cannot "
                  "remove, hold at most this fraction of the faces in excess of the rest's "
                  "resolution; it removes at least 15% (0: geometric rounds only)")
      ->check(CLI::Range(0.0, 0.5))
      ->capture_default_str();
  cmd->add_option("--extra-round-faces", args->extra_round_faces,
                  "With --parallel: past the handover, more rounds in even steps to the target "
                  "(none removing less than 15% of its faces) while the next would leave each "
                  "subset at least this many faces and the last one removed at least 90% of what "
                  "it was asked (or at least half, with 2.5x as many faces per subset) (0: none)")
      ->capture_default_str();
  cmd->add_option("--min-subset-faces", args->min_subset_faces,
                  "With --parallel: every round cuts the mesh into at most (its faces / this) "
                  "subsets, so a small mesh gets fewer than P (below 2, the rounds end and the "
                  "final pass does the rest); 0: P subsets in every scheduled round (default: " +
                      std::to_string(subset_faces_by_metric(true)) + " for the energy, " +
                      std::to_string(subset_faces_by_metric(false)) +
                      " for the quadric, which does a tenth of the energy's work per face)")
      ->check(CLI::Range(int64_t{0}, int64_t{1} << 40));
  cmd->add_flag(
      "--no-carry-keys", args->no_carry_keys,
      "With --parallel: every round's jobs cost all their edges again instead of "
      "starting from the queue keys (and deferred edges) the round before left (for "
      "measuring the work they save; the PM differs a little, docs/decisions/notebook-2026-11.md)");
  cmd->add_flag("--no-band-pass", args->no_band_pass,
                "With --parallel: no sequential pass over what two rounds' borders both kept "
                "after each round; the next round's jobs and the final pass take it (for "
                "measuring; the PM differs, docs/decisions/notebook-2026-11.md)");
  cmd->add_flag("--no-carry-deferred", args->no_carry_deferred,
                "With --parallel: the edges a round's jobs left deferred are costed afresh by "
                "the next round's jobs, not queued deferred again (for measuring the work it "
                "saves; the PM differs a little, docs/decisions/notebook-2026-11.md)");
  cmd->add_flag("--no-deferred-recosting", args->no_deferred_recosting,
                "Energy: cost the edges around each collapse at once, not when they reach the "
                "top of the queue (for measuring the costings deferral saves; the PM differs a "
                "little, docs/decisions/notebook-2026-11.md)");
  cmd->add_flag(
      "--json", args->json,
      "Print one JSON object on stdout: sizes, seconds (reading and repair also with a "
      "core per chunk: with --parallel P they run in P chunks), CPU seconds and costings "
      "(edges the metric costed); with --parallel, under \"parallel\": p, rounds performed, "
      "per round the partition, extraction, subset (per subset wall and CPU) and merge "
      "seconds, the queue keys and deferred edges carried, the keys reused, the final "
      "pass, the CPU and costings in all and the critical path");
  cmd->callback([args, &exit_code] { exit_code = run_simplify(*args); });
}

}  // namespace parapm::cli
