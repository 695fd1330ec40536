// Vertices by their exact place, for the welders (weld.cpp, stl_reader.cpp). Internal to
// engine/io.
#pragma once

#include <cstdint>
#include <vector>

#include "mesh/mesh.h"

namespace parapm::io {

// Open addressing on vertex ids into `positions`, which the caller owns and may append to;
// places are equal when their coordinates are bit-identical, -0 as +0. The hash is salted once
// per process: which slot a place lands in (never what first_at answers) changes from run to
// run, so that no file can be made whose places all collide (a quadratic read). Grows when
// half full; sized for `expected` vertices it never grows.
class PlaceTable {
 public:
  PlaceTable(const std::vector<Vec3>& positions, uint64_t expected);
  // The vertex listed first at v's place; v itself when none is, and v is listed.
  VertexId first_at(VertexId v);

 private:
  void list(VertexId v);
  void grow();

  const std::vector<Vec3>& positions_;
  std::vector<VertexId> slots_;
  size_t mask_ = 0;
  uint64_t listed_ = 0;
};

}  // namespace parapm::io
