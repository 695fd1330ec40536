#include "simplify/scalar_attributes.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "simplify/point_projection.h"
#include "util/error.h"

namespace parapm {
namespace {

// Weight of the pull of a group's value towards its members' present mean, in units of b0^2
// (a point on the vertex itself weighs 1): enough to fix a value no point sees, too little
// to matter once a few do.
constexpr double kPrior = 0.05;

}  // namespace

void ScalarAttributes::initialize(const AttributeLayout& layout, std::vector<float> wedge_values,
                                  double weight) {
  layout_ = layout;
  floats_ = layout.any() && weight > 0 ? layout.floats_per_wedge() : 0;
  if (floats_ > kMaxFloats) throw_internal("scalar attributes: too many floats per wedge");
  first_costed_ = layout.normals ? layout.normal_offset() + 3 : 0;
  weight_sq_ = weight * weight;
  point_values_.clear();
  residual_.clear();
  if (floats_ == 0) {
    values_.clear();
    parent_.clear();
    return;
  }
  if (wedge_values.size() % size_t(floats_) != 0)
    throw_internal("scalar attributes: wedge values do not match the layout");
  values_ = std::move(wedge_values);
  parent_.resize(values_.size() / size_t(floats_));
  for (WedgeId w = 0; w < parent_.size(); ++w) parent_[w] = w;
}

void ScalarAttributes::add_points(const CollapseMesh& mesh,
                                  const std::vector<SurfaceSample>& samples, ChunkedLoops& loops) {
  const size_t first = residual_.size();
  point_values_.resize((first + samples.size()) * size_t(floats_));
  residual_.resize(first + samples.size(), 0.0);
  loops.run(samples.size(), [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const FaceId f = samples[i].face;
      const Triangle& t = mesh.face(f);
      const auto& w = mesh.corner_wedges(f);
      const Projection p = project_on_triangle(samples[i].position, mesh.position(t[0]),
                                               mesh.position(t[1]), mesh.position(t[2]));
      float* x = point_values_.data() + (first + i) * size_t(floats_);
      for (int k = 0; k < floats_; ++k)
        x[k] = float(p.bary[0] * value(w[0])[k] + p.bary[1] * value(w[1])[k] +
                     p.bary[2] * value(w[2])[k]);
    }
  });
}

double ScalarAttributes::residual_against(uint32_t point, const std::array<WedgeId, 3>& w,
                                          const std::array<double, 3>& b) const {
  const float* x = point_values_.data() + size_t(point) * size_t(floats_);
  double sum = 0;
  for (int k = first_costed_; k < floats_; ++k) {
    const double d = x[k] - (b[0] * value(w[0])[k] + b[1] * value(w[1])[k] + b[2] * value(w[2])[k]);
    sum += d * d;
  }
  return weight_sq_ * sum;
}

WedgeId ScalarAttributes::find(WedgeId w) {
  while (parent_[w] != w) {
    parent_[w] = parent_[parent_[w]];  // path halving
    w = parent_[w];
  }
  return w;
}

void ScalarAttributes::join(WedgeId a, WedgeId b) {
  a = find(a);
  b = find(b);
  if (a != b) parent_[std::max(a, b)] = std::min(a, b);
}

WedgeId ScalarAttributes::joined_root(WedgeId root) const {
  // The smallest root linked to `root` by the pairs, each pair a link both ways: two pairs may
  // share either end (a seam's two sides both joined to one class), and all their roots are
  // then one group, whatever the order of their ids.
  std::array<WedgeId, 1 + 2 * std::tuple_size_v<decltype(joined_)>> reached{root};
  size_t count = 1;
  auto has = [&](WedgeId w) {
    return std::find(reached.begin(), reached.begin() + ptrdiff_t(count), w) !=
           reached.begin() + ptrdiff_t(count);
  };
  for (bool changed = true; changed;) {
    changed = false;
    for (int i = 0; i < joined_count_; ++i) {
      const auto [a, b] = joined_[i];
      if (has(a) == has(b)) continue;
      reached[count++] = has(a) ? b : a;
      changed = true;
    }
  }
  return *std::min_element(reached.begin(), reached.begin() + ptrdiff_t(count));
}

void ScalarAttributes::begin_star(const std::array<std::pair<WedgeId, WedgeId>, 2>& joined,
                                  int joined_count) {
  group_count_ = 0;
  joined_count_ = 0;
  for (int i = 0; i < joined_count; ++i) {
    const WedgeId a = find(joined[i].first), b = find(joined[i].second);
    if (a != b) joined_[joined_count_++] = {std::min(a, b), std::max(a, b)};
  }
}

int ScalarAttributes::group_of(WedgeId moving) {
  const WedgeId root = joined_root(find(moving));
  int g = 0;
  while (g < group_count_ && groups_[g].root != root) ++g;
  if (g == group_count_) {
    if (size_t(g) == groups_.size()) groups_.emplace_back();
    Group& group = groups_[g];
    group.root = root;
    group.a = 0;
    group.b.fill(0);
    group.c.fill(0);
    group.members.clear();
    ++group_count_;
  }
  auto& members = groups_[g].members;
  if (std::find(members.begin(), members.end(), moving) == members.end()) members.push_back(moving);
  return g;
}

void ScalarAttributes::add(int group, uint32_t point, double b0, WedgeId w1, double b1, WedgeId w2,
                           double b2) {
  Group& g = groups_[group];
  const float* x = point_values_.data() + size_t(point) * size_t(floats_);
  const float* v1 = value(w1);
  const float* v2 = value(w2);
  g.a += b0 * b0;
  for (int k = 0; k < floats_; ++k) {
    const double rest = x[k] - b1 * v1[k] - b2 * v2[k];
    g.b[k] += b0 * rest;
    g.c[k] += rest * rest;
  }
}

std::array<double, ScalarAttributes::kMaxFloats> ScalarAttributes::solve(const Group& g) const {
  std::array<double, kMaxFloats> mean{};
  for (WedgeId w : g.members)
    for (int k = 0; k < floats_; ++k) mean[k] += value(w)[k];
  const double prior = kPrior * double(g.members.size());
  std::array<double, kMaxFloats> v{};
  for (int k = 0; k < floats_; ++k) v[k] = (g.b[k] + kPrior * mean[k]) / (g.a + prior);
  // Back into each channel's range: colours in [0, 1], normals of unit length.
  if (layout_.colors)
    for (int k = layout_.color_offset(); k < layout_.color_offset() + 4; ++k)
      v[k] = std::clamp(v[k], 0.0, 1.0);
  if (layout_.normals) {
    const int o = layout_.normal_offset();
    const double length = std::sqrt(v[o] * v[o] + v[o + 1] * v[o + 1] + v[o + 2] * v[o + 2]);
    if (length > 0)
      for (int k = o; k < o + 3; ++k) v[k] /= length;
  }
  for (int k = 0; k < floats_; ++k) v[k] = double(float(v[k]));  // what the PM will store
  return v;
}

double ScalarAttributes::energy(const Group& g, const std::array<double, kMaxFloats>& v) const {
  // sum |rest - b0 v|^2 expanded: c - 2 v b + a v^2, exact for any v.
  double sum = 0;
  for (int k = first_costed_; k < floats_; ++k)
    sum += g.c[k] - 2 * v[k] * g.b[k] + g.a * v[k] * v[k];
  return weight_sq_ * std::max(0.0, sum);
}

double ScalarAttributes::star_energy() {
  double sum = 0;
  for (int g = 0; g < group_count_; ++g) sum += energy(groups_[g], solve(groups_[g]));
  return sum;
}

void ScalarAttributes::apply(std::vector<WedgeId>& changed, std::vector<float>& new_values) {
  for (int g = 0; g < group_count_; ++g) {
    const std::array<double, kMaxFloats> v = solve(groups_[g]);
    for (WedgeId w : groups_[g].members) {
      float* current = values_.data() + size_t(w) * size_t(floats_);
      bool differs = false;
      for (int k = 0; k < floats_; ++k) differs |= current[k] != float(v[k]);
      if (!differs) continue;
      changed.push_back(w);
      for (int k = 0; k < floats_; ++k) {
        current[k] = float(v[k]);
        new_values.push_back(current[k]);
      }
    }
  }
}

WedgeId ScalarAttributes::root(WedgeId w) const {
  while (parent_[w] != w) w = parent_[w];
  return w;
}

void ScalarAttributes::export_wedges(const std::vector<WedgeId>& wedges, const IdTranslation& to,
                                     EnergyState& out) const {
  if (floats_ == 0) return;
  std::unordered_map<WedgeId, WedgeId> first;  // class root -> first written wedge of it
  for (size_t i = 0; i < wedges.size(); ++i) {
    const WedgeId w = wedges[i];
    const WedgeId written = to.near(w, i);  // (exact when `wedges` is the map, a job's)
    out.wedges.push_back(written);
    out.wedge_values.insert(out.wedge_values.end(), value(w), value(w) + floats_);
    out.wedge_class.push_back(first.try_emplace(root(w), written).first->second);
  }
}

void ScalarAttributes::import_local(const AttributeLayout& layout, double weight,
                                    const EnergyState& state) {
  initialize(layout, state.wedge_values, weight);
  if (floats_ == 0) return;
  for (size_t i = 0; i < state.wedges.size(); ++i)
    if (state.wedges[i] != i || state.wedge_class.at(i) > i)
      throw_invalid("energy state: the job's wedges are not 0..n-1 with their classes");
  for (size_t i = 0; i < state.wedges.size(); ++i) parent_[i] = state.wedge_class[i];
  if (state.point_values.size() != state.points.size() * size_t(floats_))
    throw_invalid("energy state: point attributes disagree with the points");
  point_values_ = state.point_values;
  residual_.clear();
  for (const EnergyState::Point& p : state.points) residual_.push_back(p.residual);
}

void ScalarAttributes::check_global(const EnergyState& state) const {
  if (floats_ == 0) return;
  if (state.wedge_values.size() != state.wedges.size() * size_t(floats_) ||
      state.wedge_class.size() != state.wedges.size())
    throw_invalid("energy state: wedge values or classes disagree with the wedges");
  for (size_t i = 0; i < state.wedges.size(); ++i)
    if (state.wedges[i] >= parent_.size() || state.wedge_class[i] >= parent_.size())
      throw_invalid("energy state: wedge out of range");
}

void ScalarAttributes::import_global(const EnergyState& state) {
  if (floats_ == 0) return;
  check_global(state);
  for (size_t i = 0; i < state.wedges.size(); ++i) {
    const WedgeId w = state.wedges[i];
    std::copy_n(state.wedge_values.begin() + ptrdiff_t(i * size_t(floats_)), floats_,
                values_.begin() + ptrdiff_t(size_t(w) * size_t(floats_)));
    join(w, state.wedge_class[i]);
  }
}

}  // namespace parapm
