// The quadric priority module's placement: the volume and the border area its collapses keep
// (placement_constraints.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "drawn_meshes.h"
#include "simplify/quadric_priority.h"
#include "simplify/simplifier.h"
#include "simplify/vec_math.h"

namespace parapm {
namespace {

// The volume the live faces enclose (a closed mesh).
double enclosed_volume(const CollapseMesh& mesh) {
  double six_volumes = 0;
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!mesh.face_alive(f)) continue;
    const Triangle& t = mesh.face(f);
    six_volumes += dot(mesh.position(t[0]), cross(mesh.position(t[1]), mesh.position(t[2])));
  }
  return six_volumes / 6;
}

// The area the live faces cover (a flat mesh in z = 0, faces counter-clockwise).
double covered_area(const CollapseMesh& mesh) {
  double twice = 0;
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!mesh.face_alive(f)) continue;
    const Triangle& t = mesh.face(f);
    twice += triangle_normal(mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]))[2];
  }
  return twice / 2;
}

// A sphere taken down to 60 faces: each collapse of a convex surface cuts a little off it, so
// a level placed at the quadric's free optimum shrinks; kept on the plane of equal volume, the
// level encloses the input's volume (up to the collapses that fall back to an end or the
// midpoint).
TEST(QuadricPlacement, ACoarseSphereKeepsItsVolume) {
  const Mesh sphere = testing::uv_sphere(40, 80, 0.15);
  auto volume_ratio = [&](bool keep_volume) {
    CollapseMesh mesh(sphere);
    const double before = enclosed_volume(mesh);
    QuadricOptions options;
    options.keep_volume = keep_volume;
    options.keep_border = false;
    QuadricPriority priority({}, options);
    Simplifier simplifier(mesh, priority, standard_constraints({}));
    simplifier.run({60}, {}, nullptr);
    EXPECT_EQ(mesh.live_faces(), 60u);
    return enclosed_volume(mesh) / before;
  };
  const double kept = volume_ratio(true), free = volume_ratio(false);
  std::printf("volume of the 60-face level over the input's: kept %.4f, free %.4f\n", kept, free);
  EXPECT_NEAR(kept, 1.0, 0.002);
  EXPECT_LT(free, 0.99);
}

// A flat disc of 80 border edges taken down to 12 faces: a border collapse placed by the
// quadric alone (its border planes) cuts a chord off the outline; kept on the placements that
// keep the area the border sweeps, the level covers the input's area.
TEST(QuadricPlacement, ACoarseDiscKeepsItsArea) {
  const Mesh disc = testing::disc(10, 80);
  auto area_ratio = [&](bool keep_border) {
    CollapseMesh mesh(disc);
    const double before = covered_area(mesh);
    QuadricOptions options;
    options.keep_border = keep_border;
    QuadricPriority priority({}, options);
    Simplifier simplifier(mesh, priority, standard_constraints({}));
    simplifier.run({12}, {}, nullptr);
    EXPECT_EQ(mesh.live_faces(), 12u);
    return covered_area(mesh) / before;
  };
  const double kept = area_ratio(true), free = area_ratio(false);
  std::printf("area of the 12-face level over the input's: kept %.4f, free %.4f\n", kept, free);
  EXPECT_NEAR(kept, 1.0, 0.002);
  EXPECT_LT(free, 0.99);
}

}  // namespace
}  // namespace parapm
