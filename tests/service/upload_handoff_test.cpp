// The hand-off of an upload's parsed mesh to the job that follows it: taken once, by the
// upload's own hash only, replaced by the next upload, and freed when no job takes it in time.
#include <gtest/gtest.h>

#include <thread>

#include "upload_handoff.h"

namespace parapm::service {
namespace {

using std::chrono::milliseconds;

std::shared_ptr<const RepairedMesh> mesh_of(size_t faces) {
  auto repaired = std::make_shared<RepairedMesh>();
  repaired->mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  repaired->mesh.faces.assign(faces, {0, 1, 2});
  return repaired;
}

TEST(UploadHandoff, TheUploadsOwnJobTakesItOnce) {
  UploadHandoff handoff(milliseconds(60000));
  const auto first = mesh_of(1);
  handoff.put("aaa", first);
  EXPECT_EQ(handoff.take("bbb"), nullptr) << "another mesh's job";
  EXPECT_EQ(handoff.take("aaa"), first);
  EXPECT_EQ(handoff.take("aaa"), nullptr) << "a second job reads the blob";

  const auto second = mesh_of(2), third = mesh_of(3);
  handoff.put("bbb", second);
  handoff.put("ccc", third);
  EXPECT_EQ(handoff.take("bbb"), nullptr) << "replaced by the next upload";
  EXPECT_EQ(handoff.take("ccc"), third);
}

TEST(UploadHandoff, NoJobInTimeFreesIt) {
  UploadHandoff handoff(milliseconds(20));
  std::weak_ptr<const RepairedMesh> held;
  {
    const auto mesh = mesh_of(4);
    held = mesh;
    handoff.put("aaa", mesh);
  }
  for (int i = 0; i < 500 && !held.expired(); ++i) std::this_thread::sleep_for(milliseconds(10));
  EXPECT_TRUE(held.expired()) << "still held 5 s after it expired";
  EXPECT_EQ(handoff.take("aaa"), nullptr);
}

}  // namespace
}  // namespace parapm::service
