// Any bytes as a mesh file: the first byte picks the name (and so the format the reader
// assumes, or detection by content), the rest is the file. Every outcome must be a mesh or
// a parapm::Error; then the repair runs on what was read. Read and repair in chunks must give
// the same (differential: any difference aborts).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static const char* const kNames[] = {"f.obj",    "f.ply",    "f.off",    "f.stl",    "f",
                                       "f.obj.gz", "f.ply.gz", "f.off.gz", "f.stl.gz", "f.gz"};
  const std::string name = kNames[data[0] % (sizeof kNames / sizeof kNames[0])];
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  parapm::ReadLimits limits;  // small, so that the fuzzer explores instead of allocating
  limits.max_bytes = 16u << 20;
  limits.max_vertices = 1u << 20;
  limits.max_faces = 1u << 20;
  // The same read and repair in chunks of a few items (as a parallel build reads): the same
  // outcome, or the fuzzer stops.
  parapm::ChunkedLoops loops(4, 1, 8);
  parapm::RepairOptions chunked;
  chunked.loops = &loops;
  std::string one_pass_error = "-", chunked_error = "-";
  parapm::Mesh one_pass_mesh, chunked_mesh;
  try {
    one_pass_mesh = parapm::read_mesh_from_memory(bytes, name, nullptr, limits);
  } catch (const parapm::Error& e) {
    one_pass_error = e.what();
  }
  try {
    chunked_mesh = parapm::read_mesh_from_memory(bytes, name, nullptr, limits, &loops);
  } catch (const parapm::Error& e) {
    chunked_error = e.what();
  }
  if (one_pass_error != chunked_error || one_pass_mesh.positions != chunked_mesh.positions ||
      one_pass_mesh.faces != chunked_mesh.faces ||
      one_pass_mesh.face_wedges != chunked_mesh.face_wedges)
    std::abort();
  if (one_pass_error != "-") return 0;
  try {
    const parapm::RepairedMesh repaired = parapm::repair_mesh(one_pass_mesh);
    if (parapm::repair_mesh(one_pass_mesh, chunked).mesh.faces != repaired.mesh.faces) std::abort();
  } catch (const parapm::Error&) {
  }
  return 0;
}
