// Shared by the parallel tests: a repaired real mesh, and a PM serialised to bytes.
#pragma once

#include <sstream>
#include <string>

#include "io/mesh_io.h"
#include "mesh/repair.h"
#include "pm/pm_file.h"
#include "test_support.h"

namespace parapm::testing {

inline RepairedMesh repaired_test_mesh(const std::string& name) {
  return repair_mesh(read_mesh(test_data(name)));
}

inline std::string pm_bytes(const ProgressiveMesh& pm) {
  std::ostringstream out;
  write_pm(pm, out);
  return out.str();
}

}  // namespace parapm::testing
