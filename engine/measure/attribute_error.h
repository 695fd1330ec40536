// An independent measure of how far a simplified mesh is from its original, in geometry and
// in attributes (colour, texture coordinates, normals), for the benchmark report.
//
// Method (the sampling side of Metro, Cignoni, Rocchini, Scopigno 1998, extended to attributes
// as in Hoppe 96 section 4.2, where E_scalar compares attributes at closest points):
//  1. draw `samples` points on the reference, uniformly by area, each carrying its attributes
//     interpolated barycentrically from its face's corner wedges;
//  2. find, for each, the exact closest point of the approximation (a uniform grid over its
//     faces, searched in shells until no unvisited cell can hold anything closer);
//  3. interpolate the approximation's attributes there and accumulate the differences.
// This is one-sided (reference -> approx): it answers "how well does the approximation stand in
// for the original at the original's points", which is what a viewer of the original expects.
// Where the approximation overlaps itself (faces folded onto each other, self-intersections),
// several faces are at the same distance and the first one met wins, with its own attributes:
// such a mesh measured against itself can show a few large normal or colour differences
// (beetle-2k: one sample of 200000 at 98 degrees, from two coplanar folded slivers).
//
// Nothing here is shared with the simplifier's own error bookkeeping (only the generator and
// the point-triangle projection), so a bug in one does not hide in the other.
#pragma once

#include <cstdint>

#include "mesh/mesh.h"

namespace parapm {

struct AttributeErrorOptions {
  uint64_t samples = 200000;  // points drawn on the reference; must be positive
  uint64_t seed = 1;          // the same meshes, samples and seed give the same figures
};

struct AttributeError {
  uint64_t samples = 0;
  double diagonal = 0;  // bounding-box diagonal of the reference's sampled faces, model units
  // Distance from each sample to the closest point of the approximation, model units.
  double distance_rms = 0, distance_max = 0;
  // Channels present in BOTH meshes; the figures of a channel are 0 when it is false.
  bool colors = false, texcoords = false, normals = false;
  double color_rms = 0, color_max = 0;        // Euclidean RGB distance (alpha ignored), in [0, 1]
  double texcoord_rms = 0, texcoord_max = 0;  // Euclidean UV distance
  // Angle between the interpolated normals, each normalised first. Samples where either
  // interpolated normal is zero (opposite wedge normals cancelling) have no direction: they
  // are left out of these two figures and counted in normal_samples_skipped.
  double normal_rms_degrees = 0, normal_max_degrees = 0;
  uint64_t normal_samples_skipped = 0;
};

// Measures `approx` against `reference` (see the method above). Faces with zero area are
// skipped in both meshes: they hold no area to sample, and every point of such a face is also
// a point of a segment it shares with the surface around it. Error(kInvalidInput): corner or
// wedge ids out of range, wedge arrays whose sizes disagree with the layout, non-finite
// coordinates or attribute values, a mesh without a face of positive area, options.samples
// == 0.
//
// Cost: O(F_approx) to build the grid (closest_point.h), then each sample visits the few cells
// around it when the approximation is close to the reference: O(samples). Memory: the grid
// (tens of bytes per approx face) and 12 bytes per reference face. Single-threaded; the meshes
// are only read.
AttributeError measure_attribute_error(const Mesh& reference, const Mesh& approx,
                                       const AttributeErrorOptions& options = {});

}  // namespace parapm
