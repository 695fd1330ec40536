// Hashing a position by its exact coordinates, for the welders (weld.cpp, stl_reader.cpp).
// Internal to engine/io.
#pragma once

#include <cstdint>

#include "mesh/mesh.h"

namespace parapm::io {

// The bit pattern of a coordinate, with -0 folded onto +0 (equal coordinates, different bits).
uint64_t coordinate_key(double c);
// Whether two positions are at exactly the same place (their coordinate keys agree).
bool same_place(const Vec3& a, const Vec3& b);
// A hash of the place, salted once per process: which slot a place lands in (never what a
// welder computes) changes from run to run, so that no file can be made whose places all
// collide (a quadratic read).
uint64_t place_hash(const Vec3& p);

}  // namespace parapm::io
