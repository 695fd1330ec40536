#include "cli_common.h"

#include <parapm/openmesh.h>

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>

#include <spdlog/spdlog.h>

namespace parapm::cli {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), enabled_(isatty(STDERR_FILENO) != 0) {}

ProgressBar::~ProgressBar() { finish(); }

ProgressCallback ProgressBar::callback() {
  if (!enabled_) return {};
  return [this](uint64_t done, uint64_t total) { draw(done, total); };
}

void ProgressBar::draw(uint64_t done, uint64_t total) {
  const int permille = total == 0 ? 1000 : int(std::min<uint64_t>(1000, done * 1000 / total));
  if (permille == last_permille_) return;
  last_permille_ = permille;
  constexpr int kWidth = 40;
  const int filled = permille * kWidth / 1000;
  std::string bar(size_t(filled), '=');
  if (filled < kWidth) bar += '>';
  bar.resize(kWidth, ' ');
  std::fprintf(stderr, "\r%s [%s] %3d%%", label_.c_str(), bar.c_str(), permille / 10);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (enabled_ && last_permille_ >= 0 && !finished_) std::fprintf(stderr, "\n");
  finished_ = true;
}

LoadedMesh load_and_repair(const std::string& path, const RepairOptions& options) {
  LoadedMesh loaded;
  auto start = std::chrono::steady_clock::now();
  // .om: OpenMesh's own format, through its reader (ParaPM's readers do the others).
  const bool openmesh_file = path.size() > 3 && (path.compare(path.size() - 3, 3, ".om") == 0 ||
                                                 path.compare(path.size() - 3, 3, ".OM") == 0);
  ChunkedLoops one_thread;
  const LoopClock read_clock(options.loops ? *options.loops : one_thread);
  Mesh mesh = openmesh_file ? openmesh::read_openmesh(path)
                            : read_mesh(path, &loaded.read, {}, options.loops);
  loaded.read_seconds = seconds_since(start);
  loaded.read_critical_seconds = read_clock.critical_seconds();
  loaded.input_vertices = mesh.vertex_count();
  loaded.input_faces = mesh.face_count();
  start = std::chrono::steady_clock::now();
  const LoopClock repair_clock(options.loops ? *options.loops : one_thread);
  loaded.repaired = repair_mesh(mesh, options);
  loaded.repair_seconds = seconds_since(start);
  loaded.repair_critical_seconds = repair_clock.critical_seconds();
  const RepairReport& r = loaded.repaired.report;
  spdlog::info("read {}: {} vertices, {} faces ({}) in {:.3f} s", path, loaded.input_vertices,
               loaded.input_faces,
               openmesh_file ? "om, OpenMesh's reader" : format_name(loaded.read.format),
               loaded.read_seconds);
  if (r.changed())
    spdlog::info(
        "repaired {}: removed {} degenerate and {} duplicate faces, {} unreferenced vertices; "
        "split {} non-manifold vertices ({} copies) along {} non-manifold edges",
        path, r.degenerate_faces_removed, r.duplicate_faces_removed,
        r.unreferenced_vertices_removed, r.nonmanifold_vertices, r.vertex_copies_added,
        r.nonmanifold_edges);
  if (loaded.read.welded_vertices > 0 && loaded.read.format != MeshFormat::kStl)
    spdlog::info(
        "welded {}: {} vertices at exactly the place of an earlier one (their faces "
        "now share it)",
        path, loaded.read.welded_vertices);
  for (const std::string& what : loaded.read.ignored) spdlog::info("ignored: {}", what);
  return loaded;
}

nlohmann::json repair_report_json(const RepairReport& r) {
  return {{"degenerate_faces_removed", r.degenerate_faces_removed},
          {"duplicate_faces_removed", r.duplicate_faces_removed},
          {"unreferenced_vertices_removed", r.unreferenced_vertices_removed},
          {"nonmanifold_edges", r.nonmanifold_edges},
          {"nonmanifold_vertices", r.nonmanifold_vertices},
          {"vertex_copies_added", r.vertex_copies_added},
          {"zero_area_faces", r.zero_area_faces}};
}

void print_json(const nlohmann::json& object) { std::cout << object.dump() << std::endl; }

}  // namespace parapm::cli
