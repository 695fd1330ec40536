// Exact comparison of two meshes, for `parapm check` and the tests: does a Progressive Mesh
// give back its input bit for bit?
//
// Equal means: the same attribute layout and counts; positions equal bit for bit (so -0.0
// differs from 0.0, and a NaN equals only the same NaN); faces equal with the same
// orientation, a face may be rotated ((a,b,c) == (b,c,a)) but not reflected; at every corner
// the wedge's attribute values equal bit for bit. Wedge numbering and wedge_vertex are not
// compared (only the values seen at each corner), nor is positions_are_float.
//
// With same_numbering, vertex i of a is vertex i of b and face i is face i. Without, vertices
// may be renumbered and faces reordered: then the multisets of vertex positions must agree,
// and the multisets of faces written as per-corner (position bits, wedge value bits) tuples,
// each rotated to its smallest start. (Two vertices at the same position are then
// interchangeable, which is as far as positions can tell.)
#pragma once

#include <string>

#include "mesh/mesh.h"

namespace parapm {

struct MeshDifference {
  bool equal = true;
  std::string first_difference;  // empty when equal, else the first difference in words
  explicit operator bool() const { return !equal; }  // true when the meshes differ
};

MeshDifference compare_meshes_exact(const Mesh& a, const Mesh& b, bool same_numbering);

}  // namespace parapm
