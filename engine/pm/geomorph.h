// Geomorphs between two levels of a Progressive Mesh (Hoppe 96, section 4.2): the fine
// level's mesh whose vertices glide from where their ancestors are in the coarse level
// (alpha = 0) to their own positions (alpha = 1), so that switching levels does not pop.
//
// ancestor(v) = v when v exists at the coarse level, else ancestor(vs of the split that
// created v). The start position of v is the position of ancestor(v) *at the coarse level*
// (vs moves at every split it takes part in, so its position when v was created would be
// wrong). At alpha = 0 every face created between the two levels has two corners on one
// ancestor and zero area; dropping those leaves exactly the coarse level's faces, written
// with ancestors.
//
// Wedge values (simple rule, positions are what matters): a wedge of the fine mesh whose PM
// wedge exists at the coarse level starts from that PM wedge's value at the coarse level; a
// wedge introduced between the levels keeps its fine value throughout. Those are only used by
// faces created between the levels (corner wedges never change once a face exists), which
// have zero area at alpha = 0 and grow from there, so the constant value does not show.
#pragma once

#include <cstddef>
#include <vector>

#include "mesh/mesh.h"
#include "pm/progressive_mesh.h"

namespace parapm {

struct Geomorph {
  size_t coarse_level = 0;
  size_t fine_level = 0;
  Mesh fine;                               // the fine level, as PmCursor::extract gives it
  std::vector<VertexId> ancestor;          // per vertex of `fine`: its ancestor at the coarse level
  std::vector<Vec3> coarse_positions;      // per vertex of `fine`: its ancestor's coarse position
  std::vector<float> coarse_wedge_values;  // per wedge of `fine`, as fine.wedge_values

  // The mesh at blend `alpha` in [0, 1]: positions (1 - alpha) * coarse + alpha * fine, wedge
  // values likewise. alpha = 1 is `fine` bit for bit; alpha = 0 gives the coarse positions
  // exactly. positions_are_float is kept at both ends and false in between. Throws
  // Error(kInvalidInput) for alpha outside [0, 1] or NaN.
  Mesh at(double alpha) const;
};

// Throws Error(kInvalidInput) unless coarse_level <= fine_level <= pm.splits.size(), or when
// the PM is corrupt.
Geomorph make_geomorph(const ProgressiveMesh& pm, size_t coarse_level, size_t fine_level);

}  // namespace parapm
