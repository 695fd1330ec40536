// Each vertex's outgoing halfedges (a face's corner's edge, in the face's direction), gathered
// by a counting sort: linear in the faces, for the repair's and the copy groups' lookups of a
// halfedge around its tail.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "mesh/mesh.h"

namespace parapm {

struct OutgoingHalfedges {
  struct Halfedge {
    VertexId to;
    FaceId face;
  };
  // Vertex v's: halfedges[begin[v] .. begin[v + 1]), in face order.
  std::vector<uint32_t> begin;
  std::vector<Halfedge> halfedges;

  std::span<Halfedge> of(VertexId v) {
    return {halfedges.data() + begin[v], halfedges.data() + begin[v + 1]};
  }
  std::span<const Halfedge> of(VertexId v) const {
    return {halfedges.data() + begin[v], halfedges.data() + begin[v + 1]};
  }
};

// Every corner of `faces` must name a vertex below vertex_count.
OutgoingHalfedges outgoing_halfedges(const std::vector<Triangle>& faces, size_t vertex_count);

}  // namespace parapm
