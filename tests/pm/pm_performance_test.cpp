// Performance of the PM operations on a 1M-face Progressive Mesh (500k splits of an
// octahedron): applying every split must take well under a second in an optimised build.
// The bound asserted is looser (shared CI machines); the times are printed.
#include <gtest/gtest.h>

#include <chrono>
#include <sstream>

#include "pm/pm_cursor.h"
#include "pm/pm_file.h"
#include "pm/selective_refinement.h"
#include "pm_fixtures.h"
#include "test_support.h"

namespace parapm {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(PmPerformance, MillionFacePm) {
  const size_t splits = 500000;
  auto start = std::chrono::steady_clock::now();
  const ProgressiveMesh pm = testing::random_pm(splits, {true, false, true, 1});
  std::printf("  generated %zu splits in %.3f s\n", splits, seconds_since(start));
  ASSERT_EQ(pm.full_face_count(), 8 + 2 * splits);

  start = std::chrono::steady_clock::now();
  PmCursor cursor(pm);
  cursor.go_to_level(splits);
  const double apply = seconds_since(start);
  start = std::chrono::steady_clock::now();
  cursor.go_to_level(0);
  const double undo = seconds_since(start);
  std::printf("  apply all: %.3f s, undo all: %.3f s\n", apply, undo);
#ifdef NDEBUG
  EXPECT_LT(apply, 2.0);
  EXPECT_LT(undo, 2.0);
#endif

  cursor.go_to_level(splits);
  start = std::chrono::steady_clock::now();
  const Mesh full = cursor.extract();
  std::printf("  extract: %.3f s\n", seconds_since(start));
  EXPECT_EQ(full.face_count(), pm.full_face_count());

  start = std::chrono::steady_clock::now();
  validate_pm(pm);
  std::printf("  validate: %.3f s\n", seconds_since(start));

  start = std::chrono::steady_clock::now();
  std::ostringstream out(std::ios::binary);
  write_pm(pm, out);
  const std::string bytes = out.str();
  std::printf("  write: %.3f s, %zu bytes (%.1f bytes/face)\n", seconds_since(start), bytes.size(),
              double(bytes.size()) / double(full.face_count()));
  start = std::chrono::steady_clock::now();
  std::istringstream in(bytes, std::ios::binary);
  const ProgressiveMesh read = read_pm(in);
  std::printf("  read (with validation): %.3f s\n", seconds_since(start));
  EXPECT_EQ(read.splits.size(), splits);

  start = std::chrono::steady_clock::now();
  const SelectiveRefinement r = selectively_refine(pm, [](VertexId, const Vec3&) { return true; });
  std::printf("  selective refinement, every split: %.3f s\n", seconds_since(start));
  EXPECT_EQ(r.applied, splits);
}

}  // namespace
}  // namespace parapm
