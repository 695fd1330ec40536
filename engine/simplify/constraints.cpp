// The standard constraint modules: topology (Hoppe 96 section 3; Dey et al. 1999 for the link
// condition) and geometry (no flipped or degenerate faces).
#include <algorithm>
#include <cmath>
#include <utility>

#include "simplify/face_fold.h"
#include "simplify/modules.h"
#include "simplify/vec_math.h"
#include "util/error.h"

namespace parapm {
namespace {

class LockedVertices : public ConstraintModule {
 public:
  explicit LockedVertices(std::vector<uint8_t> locked) : locked_(std::move(locked)) {}
  std::string name() const override { return "locked-vertices"; }
  bool star_local() const override { return true; }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces&) const override {
    if (locked_.empty()) return true;
    if (c.seam) return true;  // the simplifier keeps each group at one place
    if (locked_[c.vt]) return false;
    return !locked_[c.vs] || c.position == mesh.position(c.vs);
  }

 private:
  std::vector<uint8_t> locked_;
};

// Counts the live vertices of each connected component; components never merge or split
// under legal collapses, so the counts only go down by one per collapse. A closed component
// keeps a tetrahedron (a closed surface has no smaller form), an open one its last triangle,
// unless components may vanish: then an open component may lose it too, but for the largest
// (by area when the pass starts), so that the mesh never vanishes whole, and those touching
// another component (mark_touching_components).
class ComponentMinimum : public ConstraintModule {
 public:
  ComponentMinimum(std::shared_ptr<const std::vector<uint32_t>> components, bool may_vanish,
                   std::vector<uint8_t> on_membrane)
      : given_(std::move(components)),
        may_vanish_(may_vanish),
        on_membrane_(std::move(on_membrane)) {}
  std::string name() const override { return "component-minimum"; }
  bool topological() const override { return true; }
  void initialize(const CollapseMesh& mesh) override {
    if (given_) {
      if (given_->size() != mesh.vertex_capacity())
        throw_internal("component-minimum: the given components are of another mesh");
      component_ = given_->data();
    } else {
      connected_components(mesh, found_);
      component_ = found_.data();
    }
    // One pass over the live vertices, the counts growing to the largest component seen.
    count_.clear();
    closed_.clear();
    for (VertexId v = 0; v < mesh.vertex_capacity(); ++v) {
      if (!mesh.vertex_alive(v)) continue;
      const uint32_t c = component_[v];
      if (c == kNoId) throw_internal("component-minimum: a live vertex has no component");
      if (c >= count_.size()) {
        count_.resize(size_t(c) + 1, 0);
        closed_.resize(size_t(c) + 1, 1);
      }
      ++count_[c];
      if (mesh.is_boundary(v)) closed_[c] = 0;
    }
    if (may_vanish_) {
      largest_ = largest_component(mesh);
      mark_touching_components(mesh);
    }
  }
  bool allows(const CollapseMesh&, const CollapseCandidate& c, const EdgeFaces&) const override {
    const uint32_t comp = component_[c.vs];
    return count_[comp] > smallest(comp);
  }
  void drop_too_small(const CollapseMesh&, std::vector<SeamPair>& collapses) const override {
    // Where every collapse's component could take them all, none is dropped.
    if (std::all_of(collapses.begin(), collapses.end(), [&](const SeamPair& c) {
          const uint32_t comp = component_[c.vs];
          return count_[comp] > smallest(comp) + collapses.size();
        }))
      return;
    std::vector<std::pair<uint32_t, uint32_t>> made;  // (component, collapses kept in it)
    std::erase_if(collapses, [&](const SeamPair& c) {
      const uint32_t comp = component_[c.vs];
      auto it =
          std::find_if(made.begin(), made.end(), [&](const auto& m) { return m.first == comp; });
      if (it == made.end()) it = made.insert(made.end(), {comp, 0u});
      if (count_[comp] - it->second <= smallest(comp)) return true;
      ++it->second;
      return false;
    });
  }
  void collapsed(const CollapseMesh&, const CollapseCandidate& c) override {
    --count_[component_[c.vs]];
  }

 private:
  // A collapse in component comp needs more live vertices than this.
  uint32_t smallest(uint32_t comp) const {
    if (closed_[comp]) return 4;
    return may_vanish_ && comp != largest_ && !touching_[comp] ? 2 : 3;
  }

  // The component of the largest area (the first of equals): the one kept whatever the cost.
  uint32_t largest_component(const CollapseMesh& mesh) const {
    std::vector<double> area(count_.size(), 0.0);
    for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
      if (!mesh.face_alive(f)) continue;
      const Triangle& t = mesh.face(f);
      const Vec3& p0 = mesh.position(t[0]);
      area[component_[t[0]]] +=
          length(triangle_normal(p0, mesh.position(t[1]), mesh.position(t[2])));
    }
    return uint32_t(std::max_element(area.begin(), area.end()) - area.begin());
  }

  // Components with a vertex at the same place as another component's: pieces of one surface
  // the input did not weld (a soup of triangles), where a vanishing piece opens a hole in that
  // surface, not a part leaving the scene. They keep their last triangle. A membrane's
  // vertices lie at other components' places by the repair's making, not as pieces of one
  // surface: they are left out, so a membrane may vanish.
  void mark_touching_components(const CollapseMesh& mesh) {
    touching_.assign(count_.size(), 0);
    if (count_.size() < 2) return;
    std::vector<std::pair<Vec3, uint32_t>> placed;
    for (VertexId v = 0; v < mesh.vertex_capacity(); ++v)
      if (mesh.vertex_alive(v) && !(v < on_membrane_.size() && on_membrane_[v]))
        placed.emplace_back(mesh.position(v), component_[v]);
    std::sort(placed.begin(), placed.end());
    for (size_t i = 0; i < placed.size();) {
      size_t end = i + 1;
      bool shared = false;
      for (; end < placed.size() && placed[end].first == placed[i].first; ++end)
        shared |= placed[end].second != placed[i].second;
      if (shared)
        for (size_t k = i; k < end; ++k) touching_[placed[k].second] = 1;
      i = end;
    }
  }

  std::shared_ptr<const std::vector<uint32_t>> given_;
  bool may_vanish_;
  std::vector<uint8_t> on_membrane_;  // per vertex (may be empty): left out of the touching rule
  std::vector<uint32_t> found_;
  const uint32_t* component_ = nullptr;  // per vertex: given_'s or found_'s
  std::vector<uint32_t> count_;
  std::vector<uint8_t> closed_;
  std::vector<uint8_t> touching_;
  uint32_t largest_ = 0;
};

class BoundaryRule : public ConstraintModule {
 public:
  std::string name() const override { return "boundary"; }
  bool topological() const override { return true; }
  bool star_local() const override { return true; }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces& edge) const override {
    if (edge.left == kNoId && edge.right == kNoId) return false;  // not an edge any more
    const bool boundary_edge = edge.left == kNoId || edge.right == kNoId;
    return boundary_edge || !(mesh.is_boundary(c.vs) && mesh.is_boundary(c.vt));
  }
};

class LinkCondition : public ConstraintModule {
 public:
  std::string name() const override { return "link-condition"; }
  bool topological() const override { return true; }
  bool star_local() const override { return true; }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces& edge) const override {
    bool ok = true;
    mesh.for_each_common_neighbor(c.vs, c.vt, [&](VertexId common) {
      if (common != edge.left_apex && common != edge.right_apex) ok = false;
    });
    return ok;
  }
};

// Whether face f of `moved`'s star (not on the edge) folds when `moved` goes to c.position.
// (Inlined: the geometry rule's loop runs it for every face around both ends.)
[[gnu::always_inline]] inline bool moved_face_folds(const CollapseMesh& mesh,
                                                    const CollapseCandidate& c, VertexId moved,
                                                    FaceId f) {
  const Triangle& t = mesh.face(f);
  const Vec3& p0 = mesh.position(t[0]);
  const Vec3& p1 = mesh.position(t[1]);
  const Vec3& p2 = mesh.position(t[2]);
  const int k = corner_of(t, moved);
  return face_folds(p0, p1, p2, k == 0 ? c.position : p0, k == 1 ? c.position : p1,
                    k == 2 ? c.position : p2);
}

// Rejects a collapse after which a face around vs or vt folds (face_fold.h).
class FaceGeometry : public ConstraintModule {
 public:
  std::string name() const override { return "face-geometry"; }
  bool star_local() const override { return true; }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces& edge) const override {
    for (VertexId moved : {c.vs, c.vt}) {
      if (c.position == mesh.position(moved)) continue;  // its faces stay as they are
      for (FaceId f : mesh.faces_of(moved)) {
        if (f == edge.left || f == edge.right) continue;
        if (moved_face_folds(mesh, c, moved, f)) {
          folded_ = f;
          return false;
        }
      }
    }
    return true;
  }
  FaceId folded_face() const override { return folded_; }

 private:
  mutable FaceId folded_ = kNoId;  // the last veto's (a simplifier's rules serve one thread)
};

}  // namespace

bool collapse_folds_face(const CollapseMesh& mesh, const CollapseCandidate& c,
                         const EdgeFaces& edge, FaceId f) {
  if (!mesh.face_alive(f) || f == edge.left || f == edge.right) return false;
  for (VertexId moved : {c.vs, c.vt}) {
    if (c.position == mesh.position(moved)) continue;
    const Triangle& t = mesh.face(f);
    if ((t[0] == moved || t[1] == moved || t[2] == moved) && moved_face_folds(mesh, c, moved, f))
      return true;
  }
  return false;
}

std::vector<std::unique_ptr<ConstraintModule>> neighbourhood_constraints() {
  std::vector<std::unique_ptr<ConstraintModule>> modules;
  modules.push_back(std::make_unique<BoundaryRule>());
  modules.push_back(std::make_unique<LinkCondition>());
  modules.push_back(std::make_unique<FaceGeometry>());
  return modules;
}

std::vector<std::unique_ptr<ConstraintModule>> standard_constraints(
    const std::vector<uint8_t>& locked, std::shared_ptr<const std::vector<uint32_t>> components,
    bool components_may_vanish, std::vector<uint8_t> on_membrane) {
  std::vector<std::unique_ptr<ConstraintModule>> modules;
  modules.push_back(std::make_unique<LockedVertices>(locked));
  modules.push_back(std::make_unique<ComponentMinimum>(std::move(components), components_may_vanish,
                                                       std::move(on_membrane)));
  modules.push_back(std::make_unique<BoundaryRule>());
  modules.push_back(std::make_unique<LinkCondition>());
  modules.push_back(std::make_unique<FaceGeometry>());
  return modules;
}

}  // namespace parapm
