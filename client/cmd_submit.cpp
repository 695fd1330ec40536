// parapm submit IN [options] [--wait] [-o OUT.pm]: uploads a mesh to the coordinator and
// submits a job; with --wait (implied by -o) follows it with a progress bar to its end and
// downloads the PM.
#include <optional>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "service_client.h"
#include "service_json.h"
#include "simplify/simplify.h"

namespace parapm::cli {
namespace {

// Every option the user did not give stays unset, and the job's options leave it unset: the
// coordinator's defaults apply (parapm.proto names them).
struct SubmitArgs {
  ConnectionArgs connection;
  std::string input;
  std::string output;
  std::optional<uint64_t> faces;
  std::optional<double> ratio;
  std::string metric = "quadric";
  std::optional<std::string> quadric_placement;
  std::optional<uint32_t> parallel, rounds, crease_min_edges;
  std::optional<uint64_t> seed, extra_round_faces, min_subset_faces;
  std::optional<double> samples_per_face, crease_angle, attribute_weight, handover, border_excess;
  std::optional<double> star_planes_weight, volume_weight, spring_scale, crease_min_length;
  bool keep_order = false;
  bool free_copies = false;
  bool keep_components = false;
  bool wait = false;
  bool json = false;
};

parapm::v1::QuadricPlacement quadric_placement_of(const std::string& name) {
  if (name == "constrained") return parapm::v1::QUADRIC_PLACEMENT_CONSTRAINED;
  if (name == "free") return parapm::v1::QUADRIC_PLACEMENT_FREE;
  return parapm::v1::QUADRIC_PLACEMENT_AUTO;
}

int run_submit(SubmitArgs& args) {
  ServiceClient client(args.connection);
  const auto start = std::chrono::steady_clock::now();
  parapm::v1::UploadReply uploaded;
  {
    ProgressBar bar("upload");
    uploaded = client.upload(args.input, bar.callback());
  }
  const double upload_seconds = seconds_since(start);
  spdlog::info("uploaded {}: mesh {} ({} vertices, {} faces{}{})", args.input, uploaded.mesh_id(),
               uploaded.vertices(), uploaded.faces(),
               uploaded.repairs().empty() ? "" : "; repaired: ", uploaded.repairs());

  parapm::v1::SubmitRequest request;
  request.set_mesh_id(uploaded.mesh_id());
  parapm::v1::JobOptions& o = *request.mutable_options();
  if (args.faces) o.set_target_faces(*args.faces);
  if (args.ratio) o.set_target_ratio(*args.ratio);
  o.set_metric(args.metric == "energy" ? parapm::v1::METRIC_ENERGY : parapm::v1::METRIC_QUADRIC);
  if (args.quadric_placement)
    o.set_quadric_placement(quadric_placement_of(*args.quadric_placement));
  if (args.parallel) o.set_parallelism(*args.parallel);
  if (args.rounds) o.set_rounds(*args.rounds);
  if (args.seed) o.set_seed(*args.seed);
  if (args.samples_per_face) o.set_samples_per_face(*args.samples_per_face);
  if (args.crease_angle) o.set_crease_angle_degrees(*args.crease_angle);
  if (args.attribute_weight) o.set_attribute_weight(*args.attribute_weight);
  if (args.handover) o.set_handover_ratio(*args.handover);
  if (args.border_excess) o.set_border_excess(*args.border_excess);
  if (args.extra_round_faces) o.set_extra_round_faces(*args.extra_round_faces);
  if (args.min_subset_faces) o.set_min_subset_faces(*args.min_subset_faces);
  parapm::v1::EnergyTuning& e = *o.mutable_energy();
  if (args.star_planes_weight) e.set_star_planes_weight(*args.star_planes_weight);
  if (args.volume_weight) e.set_volume_weight(*args.volume_weight);
  if (args.spring_scale) e.set_spring_scale(*args.spring_scale);
  if (args.crease_min_length) e.set_crease_min_length(*args.crease_min_length);
  if (args.crease_min_edges) e.set_min_crease_edges(*args.crease_min_edges);
  o.set_keep_order(args.keep_order);
  o.set_free_copies(args.free_copies);
  o.set_keep_components(args.keep_components);
  parapm::v1::Job job;
  {
    auto context = client.context();
    check_status(client.stub().Submit(context.get(), request, &job), "submit", client.server());
  }
  spdlog::info("job {} submitted", job.job_id());
  if (!args.wait && args.output.empty()) {
    if (args.json)
      print_json(job_json(job));
    else
      std::printf("%s\n", job.job_id().c_str());
    return 0;
  }
  const auto wait_start = std::chrono::steady_clock::now();
  {
    ProgressBar bar("job " + job.job_id());
    ProgressCallback draw = bar.callback();
    job = client.watch(job.job_id(), [&](const parapm::v1::JobEvent& event) {
      if (event.has_progress()) {
        if (draw) draw(event.progress().done(), event.progress().total());
      } else {
        spdlog::debug("job {}: {}", job.job_id(), describe_event(event));
      }
    });
  }
  if (job.state() != parapm::v1::DONE) {
    std::fprintf(stderr, "parapm: job %s %s%s%s\n", job.job_id().c_str(),
                 job_state_name(job.state()), job.failure_reason().empty() ? "" : ": ",
                 job.failure_reason().c_str());
    if (args.json) print_json(job_json(job));
    return 1;
  }
  const double wait_seconds = seconds_since(wait_start);
  const auto download_start = std::chrono::steady_clock::now();
  uint64_t bytes = 0;
  if (!args.output.empty()) bytes = client.download(job.job_id(), args.output);
  if (args.json) {
    nlohmann::json out = job_json(job);
    // The client's view of the time: upload, waiting for the job, download.
    out["client"] = {{"upload_seconds", upload_seconds},
                     {"wait_seconds", wait_seconds},
                     {"download_seconds", seconds_since(download_start)},
                     {"total_seconds", seconds_since(start)}};
    if (!args.output.empty()) out["output"] = {{"path", args.output}, {"bytes", bytes}};
    print_json(out);
  } else {
    std::printf("job %s done: %llu -> %llu faces, %llu vsplits in %.3f s%s%s\n",
                job.job_id().c_str(), (unsigned long long)job.input_faces(),
                (unsigned long long)job.base_faces(), (unsigned long long)job.vsplits(),
                job.seconds(), args.output.empty() ? "" : "; wrote ", args.output.c_str());
  }
  return 0;
}

}  // namespace

void add_submit_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<SubmitArgs>();
  CLI::App* cmd = app.add_subcommand(
      "submit",
      "upload a mesh to the coordinator and build its Progressive Mesh there; --wait follows "
      "the job, -o downloads the .pm (same bytes as 'parapm simplify --parallel P')");
  cmd->add_option("input", args->input, "mesh file (OBJ, PLY, OFF, STL; optionally .gz)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "write the .pm here when done (implies --wait)");
  auto* faces = cmd->add_option("--faces", args->faces, "target base mesh faces");
  cmd->add_option("--ratio", args->ratio, "target base mesh faces as a ratio of the input")
      ->check(CLI::Range(1e-9, 1.0))
      ->excludes(faces);
  cmd->add_option("--metric", args->metric, "quadric or energy")
      ->check(CLI::IsMember({"quadric", "energy"}))
      ->capture_default_str();
  cmd->add_option("--quadric-placement", args->quadric_placement,
                  "quadric: auto (the optimum at fine levels, volume and border kept at coarse "
                  "ones; the default), constrained (kept at every level: slower) or free (the "
                  "optimum at every level: fastest, coarse levels drift)")
      ->check(CLI::IsMember(quadric_placements()));
  cmd->add_option("--parallel", args->parallel,
                  "subsets p (default: the coordinator's --parallelism)")
      ->check(CLI::Range(1, 256));
  cmd->add_option("--rounds", args->rounds, "parallel rounds (default: by p, 2 at p = 2, 3 above)")
      ->check(CLI::Range(1, 64));
  cmd->add_option("--handover-ratio", args->handover,
                  "the rounds go down to this fraction of the input faces (default 0.1)")
      ->check(CLI::Range(1e-9, 1.0));
  cmd->add_option("--border-excess", args->border_excess,
                  "a round ends where the faces along its cut hold at most this fraction of the "
                  "faces in excess (default 0.05; 0: none, geometric rounds only)")
      ->check(CLI::Range(0.0, 0.5));
  cmd->add_option("--extra-round-faces", args->extra_round_faces,
                  "past the handover, more rounds while every subset keeps this many faces and "
                  "the last round did 90% of its share (2.5x as many faces after one that did "
                  "half) (default 2000; 0: none; else at least 50)")
      ->check(CLI::Range(uint64_t{0}, uint64_t{1} << 40));
  cmd->add_option("--min-subset-faces", args->min_subset_faces,
                  "every round cuts the mesh into at most (its faces / this) subsets (default "
                  "by the metric: 4000 for the energy, 8000 for the quadric; 0: P subsets in "
                  "every scheduled round; else at least 50)")
      ->check(CLI::Range(uint64_t{0}, uint64_t{1} << 40));
  cmd->add_option("--seed", args->seed, "seed of the randomised steps (default 1)");
  cmd->add_option("--samples-per-face", args->samples_per_face,
                  "energy: extra points per face, by area, beyond one per vertex (default 1)")
      ->check(CLI::Range(0.0, 64.0));
  cmd->add_option("--crease-angle", args->crease_angle,
                  "energy: crease angle, degrees, in [0, 180] (default 180: no creases; creases of "
                  "fewer than 8 edges and shorter than 5% of the diagonal are noise, not kept)")
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_option("--attribute-weight", args->attribute_weight,
                  "energy: weight of attributes against geometry (default 0.01; 0: not optimised)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--crease-min-edges", args->crease_min_edges,
                  "energy: creases of fewer edges (and shorter than --crease-min-length) are "
                  "noise (default 8; 1: every crease kept)")
      ->check(CLI::Range(int64_t{1}, int64_t{1000000}));
  cmd->add_option("--crease-min-length", args->crease_min_length,
                  "energy: creases shorter than this many bounding-box diagonals (and of fewer "
                  "than --crease-min-edges edges) are noise (default 0.05)")
      ->check(CLI::Range(0.0, 10.0));
  cmd->add_option("--star-planes-weight", args->star_planes_weight,
                  "energy: weight of the star's planes against the points (default 30; 0: off)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--volume-weight", args->volume_weight,
                  "energy: weight of the enclosed volume's change (default 64; 0: off)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_option("--spring-scale", args->spring_scale,
                  "energy: E_spring's kappa times this (default 0.03; 0: no springs)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_flag("--keep-order", args->keep_order, "store the input's vertex and face order");
  cmd->add_flag("--free-copies", args->free_copies,
                "the repair's copies of a non-manifold input vertex simplify like any vertex "
                "(coarser levels; the sheets part at coarse levels: cracks)");
  cmd->add_flag("--keep-components", args->keep_components,
                "every connected component keeps a triangle at every level (default: small "
                "separate open parts vanish at coarse levels)");
  cmd->add_flag("--wait", args->wait, "follow the job to its end with a progress bar");
  cmd->add_flag("--json", args->json, "print the job as one JSON object");
  add_connection_options(cmd, args->connection);
  cmd->callback([args, &exit_code] { exit_code = run_submit(*args); });
}

}  // namespace parapm::cli
