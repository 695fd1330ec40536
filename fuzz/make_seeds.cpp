// parapm-fuzz-seeds DIR: writes the binary seeds of the fuzz corpus from the engine's own
// encoders, on a drawn 10 x 10 grid (200 faces, with texture coordinates): DIR/pm/grid.pm,
// DIR/job_codec/{job,records,summary,held}-{quadric,energy} and DIR/mesh/grid.{obj,ply}, each
// prefixed by the byte that selects its decoder or name in fuzz_job_codec / fuzz_mesh_reader.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>

#include "io/byte_output.h"
#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "parallel/job_codec.h"
#include "parallel/job_state.h"
#include "parallel/simplify_subset.h"
#include "parallel/subset_job.h"
#include "partition/partition.h"
#include "pm/pm_file.h"
#include "simplify/collapse_mesh.h"
#include "simplify/modules.h"
#include "simplify/simplify.h"

namespace {

namespace fs = std::filesystem;
using namespace parapm;

Mesh grid(int n) {
  Mesh mesh;
  mesh.layout.texcoords = true;
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      mesh.positions.push_back({double(x), double(y), 0.1 * double((x * y) % 3)});
      mesh.wedge_vertex.push_back(VertexId(mesh.positions.size() - 1));
      mesh.wedge_values.push_back(float(x) / float(n));
      mesh.wedge_values.push_back(float(y) / float(n));
    }
  auto id = [&](int x, int y) { return VertexId(y * (n + 1) + x); };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      for (const Triangle& t : {Triangle{id(x, y), id(x + 1, y), id(x + 1, y + 1)},
                                Triangle{id(x, y), id(x + 1, y + 1), id(x, y + 1)}}) {
        mesh.faces.push_back(t);
        mesh.face_wedges.push_back({t[0], t[1], t[2]});
      }
    }
  return mesh;
}

void write(const fs::path& path, const std::string& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

// `job` leaving out every other item of its state that a worker may hold (as the coordinator
// sends it: held_state.h), prefixed as fuzz_job_codec reads it: the held ids' length (2 bytes,
// little-endian), the ids, the job.
std::string held_job(const SubsetJob& job) {
  const size_t items = job.state.metric == "quadric" ? job.state.quadric.vertices.size()
                                                     : job.state.energy.points.size();
  std::vector<uint32_t> held;
  for (uint32_t i = 0; i < items; i += 2) held.push_back(i);
  const std::string ids = encode_increasing_ids(held);
  return std::string{char(ids.size() & 0xff), char(ids.size() >> 8)} + ids +
         encode_subset_job(job, job.state, held);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: parapm-fuzz-seeds DIR\n");
    return 2;
  }
  const fs::path dir = argv[1];
  const RepairedMesh repaired = repair_mesh(grid(10));
  const Mesh& mesh = repaired.mesh;
  // Each prefixed by the byte that names it in fuzz_mesh_reader (0: .obj, 1: .ply).
  fs::create_directories(dir / "mesh");
  for (const auto& [extension, selector] : {std::pair{".obj", '\0'}, std::pair{".ply", '\1'}}) {
    const fs::path path = dir / "mesh" / (std::string("grid") + extension);
    write_mesh(mesh, path.string());
    std::ifstream in(path, std::ios::binary);
    const std::string bytes(std::istreambuf_iterator<char>(in), {});
    write(path, std::string(1, selector) + bytes);
  }
  for (const char* metric : {"quadric", "energy"}) {
    SimplifyOptions options;
    options.metric = metric;
    options.target_faces = 20;
    std::ostringstream pm;
    write_pm(build_progressive_mesh(repaired, options), pm);
    write(dir / "pm" / (std::string("grid-") + metric + ".pm"), pm.str());

    const std::vector<uint8_t> locked = locked_vertices(repaired);
    CollapseMesh whole(mesh);
    const auto master = make_priority_module(options, mesh, locked);
    master->initialize(whole);
    const Partition partition = partition_mesh(mesh, 2);
    std::vector<SubsetJob> jobs =
        extract_subsets(whole, mesh.layout, mesh.wedge_values, mesh.positions_are_float, locked,
                        partition.vertex_subset, 2, 0, subset_options_of(options, mesh));
    SubsetJob& job = jobs[0];
    job.state = export_job_state(*master, job);
    job.options.target_faces = job.mesh.face_count() / 2;
    // A group of copies named (the grid has none), so that the seed holds the field.
    job.copy_group.assign(job.mesh.vertex_count(), kNoId);
    job.copy_group[0] = job.copy_group[1] = 0;
    const SubsetResult result = simplify_subset(job);
    write(dir / "job_codec" / (std::string("job-") + metric),
          std::string(1, '\0') + encode_subset_job(job));
    write(dir / "job_codec" / (std::string("records-") + metric),
          std::string(1, '\1') +
              encode_collapse_records(result.records.data(), result.records.size()));
    write(dir / "job_codec" / (std::string("summary-") + metric),
          std::string(1, '\2') + encode_subset_summary(result));
    write(dir / "job_codec" / (std::string("held-") + metric), '\3' + held_job(job));
  }
  return 0;
}
