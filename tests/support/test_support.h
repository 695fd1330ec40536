// Where the tests find their meshes: the small real meshes committed under tests/data, and
// every mesh of ../shared/meshes when that folder is present (it is in CI); and a simplified
// mesh's live faces as a Mesh.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pm/pm_file.h"
#include "simplify/collapse_mesh.h"
#include "util/error.h"

namespace parapm::testing {

inline std::string test_data(const std::string& name) {
  return std::string(PARAPM_TEST_DATA_DIR) + "/" + name;
}

inline std::filesystem::path shared_meshes_dir() {
  if (const char* env = std::getenv("PARAPM_SHARED_MESHES")) return env;
  return PARAPM_SHARED_MESHES_DIR;
}

// Every mesh file of ../shared/meshes, sorted by name; empty when the folder is absent.
inline std::vector<std::filesystem::path> shared_meshes() {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  const auto dir = shared_meshes_dir();
  if (!std::filesystem::is_directory(dir, ec)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name == "README.md" || name == "INVENTORY.tsv" || !entry.is_regular_file()) continue;
    files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Runs f, expects an Error with `code` whose message contains every one of `parts`.
// Returns the message.
template <class F>
std::string expect_error(F&& f, ErrorCode code, std::initializer_list<std::string> parts) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(error_code_name(e.code()), std::string(error_code_name(code))) << e.what();
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "message: " << e.what() << "\nexpected to contain: " << part;
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "threw a non-parapm exception: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << "did not throw";
  return "";
}

// A PM's .pm bytes, for comparing two PMs exactly.
inline std::string pm_bytes(const ProgressiveMesh& pm) {
  std::ostringstream out;
  write_pm(pm, out);
  return out.str();
}

// The live faces of a simplified mesh, as a Mesh (unused vertices stay: they do not count).
inline Mesh live_mesh(const CollapseMesh& mesh) {
  Mesh out;
  out.positions = mesh.positions();
  for (FaceId f = 0; f < mesh.face_capacity(); ++f)
    if (mesh.face_alive(f)) out.faces.push_back(mesh.face(f));
  return out;
}

}  // namespace parapm::testing
