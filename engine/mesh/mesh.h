// The indexed triangle mesh every part of ParaPM exchanges: readers produce it, the repair
// step makes it engine-ready, the simplifier consumes it, and levels of detail are extracted
// as one.
//
// Attributes follow Hoppe's wedge model (PM 96, section 3.1): a wedge is one attribute set
// (normal, texture coordinate, colour) of one vertex; a vertex on an attribute seam has
// several wedges, and each face corner names the wedge it uses. A mesh whose attributes are
// per vertex (PLY) has exactly one wedge per vertex, wedge i belonging to vertex i.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace parapm {

using VertexId = uint32_t;
using FaceId = uint32_t;
using WedgeId = uint32_t;
inline constexpr uint32_t kNoId = std::numeric_limits<uint32_t>::max();

using Vec3 = std::array<double, 3>;
using Triangle = std::array<VertexId, 3>;  // counter-clockwise seen from outside

// Which attribute channels the wedges carry; values are stored interleaved in this order.
struct AttributeLayout {
  bool normals = false;    // 3 floats
  bool texcoords = false;  // 2 floats
  bool colors = false;     // 4 floats, RGBA in [0, 1]

  int floats_per_wedge() const {
    return (normals ? 3 : 0) + (texcoords ? 2 : 0) + (colors ? 4 : 0);
  }
  bool any() const { return normals || texcoords || colors; }
  int normal_offset() const { return 0; }
  int texcoord_offset() const { return normals ? 3 : 0; }
  int color_offset() const { return (normals ? 3 : 0) + (texcoords ? 2 : 0); }
  bool operator==(const AttributeLayout&) const = default;
};

struct Mesh {
  std::vector<Vec3> positions;  // per vertex, in model units
  std::vector<Triangle> faces;  // vertex ids, counter-clockwise

  // Attributes (all empty when layout.any() is false).
  AttributeLayout layout;
  std::vector<VertexId> wedge_vertex;               // wedge -> the vertex it belongs to
  std::vector<float> wedge_values;                  // layout.floats_per_wedge() per wedge
  std::vector<std::array<WedgeId, 3>> face_wedges;  // per face, the wedge of each corner

  // True when every coordinate is exactly a float32: the PM then stores float32 positions and
  // the simplifier rounds the positions it places to float32, so nothing is lost either way.
  bool positions_are_float = false;

  size_t vertex_count() const { return positions.size(); }
  size_t face_count() const { return faces.size(); }
  size_t wedge_count() const { return wedge_vertex.size(); }
  const float* wedge(WedgeId w) const {
    return wedge_values.data() + size_t(w) * size_t(layout.floats_per_wedge());
  }
};

// Axis-aligned bounding box of the referenced and unreferenced vertices alike.
struct Box {
  Vec3 min{0, 0, 0};
  Vec3 max{0, 0, 0};
  double diagonal() const;
};
Box bounding_box(const Mesh& mesh);
Box bounding_box(const std::vector<Vec3>& positions);

// x rounded to the nearest float32, as a double. The empty asm keeps GCC 12 at -O2/-O3 from
// folding the (double)(float)x pair away when it vectorises (seen here: the rounding of the
// first two coordinates of a std::array<double, 3> vanished).
inline double round_to_float(double x) {
  float f = static_cast<float>(x);
  asm("" : "+x"(f));
  return f;
}

// Recomputes positions_are_float from the coordinates.
bool all_positions_are_float(const std::vector<Vec3>& positions);

}  // namespace parapm
