// Any bytes as a mesh file: the first byte picks the name (and so the format the reader
// assumes, or detection by content), the rest is the file. Every outcome must be a mesh or
// a parapm::Error; then the repair runs on what was read.
#include <cstddef>
#include <cstdint>
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
  try {
    const parapm::Mesh mesh = parapm::read_mesh_from_memory(bytes, name, nullptr, limits);
    parapm::repair_mesh(mesh);
  } catch (const parapm::Error&) {
  }
  return 0;
}
