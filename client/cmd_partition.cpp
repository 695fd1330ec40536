// parapm partition IN -p P: split a mesh into P subsets for parallel simplification, with the
// metrics of Langis' thesis; -o writes the mesh with one colour per subset, to look at.
#include <chrono>
#include <cmath>
#include <cstdio>

#include <spdlog/spdlog.h>

#include "cli_common.h"
#include "commands.h"
#include "partition/partition.h"
#include "partition/partition_metrics.h"

namespace parapm::cli {
namespace {

struct PartitionArgs {
  std::string input;
  std::string output;
  uint32_t p = 2;
  std::string algorithm = "greedy";
  std::vector<double> weights;
  uint64_t seed = 1;
  std::string balance = "faces";
  bool refine = false;
  bool json = false;
};

// The partitioned mesh with per-vertex colours: subsets get evenly spaced hues.
Mesh coloured_by_subset(const Mesh& mesh, const Partition& partition) {
  Mesh out;
  out.positions = mesh.positions;
  out.faces = mesh.faces;
  out.positions_are_float = mesh.positions_are_float;
  out.layout.colors = true;
  out.wedge_vertex.resize(mesh.vertex_count());
  out.face_wedges.assign(mesh.faces.begin(), mesh.faces.end());
  out.wedge_values.reserve(mesh.vertex_count() * 4);
  for (VertexId v = 0; v < mesh.vertex_count(); ++v) {
    out.wedge_vertex[v] = v;
    // Golden-ratio hue steps keep neighbouring subset ids apart in colour.
    const double hue = std::fmod(partition.vertex_subset[v] * 0.618033988749895, 1.0) * 6.0;
    const double x = 1.0 - std::fabs(std::fmod(hue, 2.0) - 1.0);
    const int sector = int(hue);
    const float rgb[6][3] = {{1, float(x), 0}, {float(x), 1, 0}, {0, 1, float(x)},
                             {0, float(x), 1}, {float(x), 0, 1}, {1, 0, float(x)}};
    out.wedge_values.insert(out.wedge_values.end(), rgb[sector % 6], rgb[sector % 6] + 3);
    out.wedge_values.push_back(1.0f);
  }
  return out;
}

int run_partition(const PartitionArgs& args) {
  const LoadedMesh loaded = load_and_repair(args.input, {});
  const Mesh& mesh = loaded.repaired.mesh;
  PartitionOptions options;
  options.algorithm = args.algorithm;
  options.weights = args.weights;
  options.seed = args.seed;
  options.balance = args.balance == "vertices" ? Balance::kVertices : Balance::kFaces;
  options.refine = args.refine;
  const auto start = std::chrono::steady_clock::now();
  const Partition partition = partition_mesh(mesh, args.p, options);
  const double seconds = seconds_since(start);
  const PartitionMetrics m = partition_metrics(mesh, partition, options, seconds);
  spdlog::info("partitioned {} ({} faces) into {} subsets with {} in {:.3f} s", args.input,
               mesh.face_count(), args.p, args.algorithm, seconds);
  if (!args.output.empty()) write_mesh(coloured_by_subset(mesh, partition), args.output);

  if (args.json) {
    print_json({{"p", m.p},
                {"algo", m.algorithm},
                {"seconds", m.seconds},
                {"subset_faces", m.subset_faces},
                {"stddev_faces", m.stddev_faces},
                {"biggest_faces", m.biggest_faces},
                {"ideal_faces", m.ideal_faces},
                {"cut_faces", m.cut_faces},
                {"cut_edges", m.cut_edges},
                {"components", m.components}});
  } else {
    std::printf("%s: %zu faces into %u subsets (%s) in %.3f s\n", args.input.c_str(),
                mesh.face_count(), m.p, m.algorithm.c_str(), m.seconds);
    std::printf("biggest subset %llu faces, ideal %.1f (B/ideal %.4f), stddev %.1f faces\n",
                (unsigned long long)m.biggest_faces, m.ideal_faces,
                m.ideal_faces > 0 ? double(m.biggest_faces) / m.ideal_faces : 0.0, m.stddev_faces);
    std::printf("cut: %llu faces, %llu edges\n", (unsigned long long)m.cut_faces,
                (unsigned long long)m.cut_edges);
    std::printf("subset  faces  components\n");
    for (uint32_t i = 0; i < m.p; ++i)
      std::printf("%6u %6llu %11u\n", i, (unsigned long long)m.subset_faces[i], m.components[i]);
  }
  return 0;
}

}  // namespace

void add_partition_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<PartitionArgs>();
  CLI::App* cmd =
      app.add_subcommand("partition",
                         "Split a mesh into P subsets for parallel simplification (Ciarlet-Lamour "
                         "greedy, or round-robin BFS), balanced by faces (or vertices), and "
                         "report the thesis' metrics");
  cmd->add_option("input", args->input, "Input mesh")->required()->check(CLI::ExistingFile);
  cmd->add_option("-p", args->p, "Number of subsets, 1 to 256")
      ->required()
      ->check(CLI::Range(1u, kMaxPartitionSubsets));
  cmd->add_option("--algo", args->algorithm, "Algorithm")
      ->check(CLI::IsMember({"greedy", "bfs"}))
      ->capture_default_str();
  cmd->add_option("--weights", args->weights,
                  "Relative subset sizes (worker capacities), P comma-separated values")
      ->delimiter(',');
  cmd->add_option("--balance", args->balance,
                  "What the subset sizes count: faces (each vertex weighs its faces) or vertices")
      ->check(CLI::IsMember({"faces", "vertices"}))
      ->capture_default_str();
  cmd->add_option("--seed", args->seed,
                  "Picks the start vertex among those of least degree (greedy: at least 16, "
                  "the next degrees joining the least)")
      ->capture_default_str();
  cmd->add_option("-o,--output", args->output,
                  "Write the mesh with one vertex colour per subset (.ply or .obj)");
  cmd->add_flag("--refine", args->refine,
                "Then move boundary vertices and stray pieces to cut fewer edges, keeping every "
                "subset within 5% of its share");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args, &exit_code] { exit_code = run_partition(*args); });
}

}  // namespace parapm::cli
