// E_scalar, the attribute term of the energy (Hoppe 96 section 4.2): every sample point also
// carries the attributes of the original surface where it was drawn (colour, normal, texture
// coordinates, interpolated from its face's corner wedges), and the energy adds
//   (c_scalar)^2 * sum over points of |attributes of the point - attributes of the mesh at
//   the point's projection|^2.
// After a collapse the wedges of the surviving vertex are given the values that minimise that
// sum over the star's points, given the projections (a linear least-squares problem whose
// normal equations are again a scalar times the identity, per wedge).
//
// Wedges, so that seams stay seams (Hoppe 96 section 3.1): faces keep their corner wedge ids
// through collapses (the PM format wants it: a split does not renumber corners), so the
// vertex left after a collapse has several wedge ids. Wedges that the collapse joins (the
// corners of vs and vt in fl, and in fr: the same side of any seam) form one class from then
// on, a union-find over wedge ids, and every wedge of a class holds the same value. Wedges of
// different classes around a vertex are the two sides of a seam and are solved apart.
//
// Only wedges still used by a live corner ever change value, so a wedge's last value is the
// one it had when its last face was collapsed away: the value the PM's split that brings it
// back must introduce (pm_builder.cpp).
//
// Normals are solved like the rest (the unit direction of the least-squares fit) but their
// error is not part of the energy, so it does not order the collapses: normals follow the
// geometry. Costing them let the normal term rule the order, and made both the geometry and
// the normals worse (decisions/notebook-2026-11.md, "Normals follow the geometry").
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "simplify/collapse_mesh.h"
#include "simplify/module_state.h"
#include "simplify/surface_samples.h"

namespace parapm {

class ScalarAttributes {
 public:
  static constexpr int kMaxFloats = 9;  // normals 3 + texture coordinates 2 + colour 4

  // weight: c_scalar in model units per unit of attribute: an attribute difference of 1 costs
  // as much as a distance of `weight`. E_scalar is off when the layout has no attributes or
  // the weight is not positive.
  void initialize(const AttributeLayout& layout, std::vector<float> wedge_values, double weight);
  bool enabled() const { return floats_ > 0; }
  const float* value(WedgeId w) const { return values_.data() + size_t(w) * size_t(floats_); }

  int floats() const { return floats_; }
  const float* point_values(uint32_t point) const {
    return point_values_.data() + size_t(point) * size_t(floats_);
  }

  // State export/import for the parallel construction (module_state.h). export_wedges writes
  // `wedges` (the module's ids) through `to`, with their values and classes, to out.
  // import_local starts a job's attributes from a state whose wedges are 0..n-1 and whose
  // points are the job's (values and residuals in state order), instead of initialize() and
  // add_points(). import_global gives the master the state's wedge values and classes.
  void export_wedges(const std::vector<WedgeId>& wedges, const IdTranslation& to,
                     EnergyState& out) const;
  void import_local(const AttributeLayout& layout, double weight, const EnergyState& state);
  void import_global(const EnergyState& state);  // after check_global (kInvalidInput)
  void check_global(const EnergyState& state) const;

  // The next points' attributes, the samples' in order: those of the mesh where each projects
  // on its face (residual 0), computed in `loops`' chunks.
  void add_points(const CollapseMesh& mesh, const std::vector<SurfaceSample>& samples,
                  ChunkedLoops& loops);
  // The point's weighted squared attribute error as of the last collapse that moved it.
  double residual(uint32_t point) const { return residual_[point]; }
  // The weighted squared error of the point against the mesh at corners w, barycentric b.
  double residual_against(uint32_t point, const std::array<WedgeId, 3>& w,
                          const std::array<double, 3>& b) const;
  void set_residual(uint32_t point, double r) { residual_[point] = r; }

  // One star: the faces around the moving vertex (by the wedge of their moving corner) and
  // the points that project on them. `joined` are pairs of wedges that the collapse being
  // costed would join (not yet merged): they are solved as one.
  void begin_star(const std::array<std::pair<WedgeId, WedgeId>, 2>& joined, int joined_count);
  int group_of(WedgeId moving);
  // A point projecting at barycentric (b0, b1, b2) on a face of `group` whose other corners
  // have wedges w1, w2.
  void add(int group, uint32_t point, double b0, WedgeId w1, double b1, WedgeId w2, double b2);
  // The weighted attribute energy of the star's points with each group at its best value.
  double star_energy();

  // The performed collapse: join two wedges' classes for good.
  void join(WedgeId a, WedgeId b);
  // Gives every group's wedges their best value; appends each wedge whose value changed and
  // its new values (floats per wedge each).
  void apply(std::vector<WedgeId>& changed, std::vector<float>& new_values);

 private:
  struct Group {
    WedgeId root = kNoId;
    double a = 0;                      // sum of b0^2
    std::array<double, kMaxFloats> b;  // sum of b0 * (x - b1 w1 - b2 w2), per float
    std::array<double, kMaxFloats> c;  // sum of |x - b1 w1 - b2 w2|^2, per float
    std::vector<WedgeId> members;      // distinct wedges of the moving corner
  };
  WedgeId find(WedgeId w);
  WedgeId root(WedgeId w) const;  // find without path halving
  WedgeId joined_root(WedgeId root) const;
  // The group's value minimising its error (with a weak pull to its members' mean, so that
  // a group few points see stays put), clamped to the channel's range.
  std::array<double, kMaxFloats> solve(const Group& g) const;
  double energy(const Group& g, const std::array<double, kMaxFloats>& value) const;

  AttributeLayout layout_;
  int floats_ = 0;
  // The first float that E_scalar costs: normals (the first three when present) are solved
  // like the other attributes but cost nothing (see the top).
  int first_costed_ = 0;
  double weight_sq_ = 0;
  std::vector<float> values_;        // per wedge, the current values
  std::vector<WedgeId> parent_;      // union-find of wedge classes
  std::vector<float> point_values_;  // per point, its attributes
  std::vector<double> residual_;     // per point
  std::vector<Group> groups_;        // of the present star (reused)
  int group_count_ = 0;
  std::array<std::pair<WedgeId, WedgeId>, 2> joined_{};  // roots, smaller first
  int joined_count_ = 0;
};

}  // namespace parapm
