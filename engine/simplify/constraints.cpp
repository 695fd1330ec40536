// The standard constraint modules: topology (Hoppe 96 section 3; Dey et al. 1999 for the link
// condition) and geometry (no flipped or degenerate faces).
#include <algorithm>
#include <cmath>
#include <utility>

#include "simplify/face_fold.h"
#include "simplify/modules.h"
#include "util/error.h"

namespace parapm {
namespace {

class LockedVertices : public ConstraintModule {
 public:
  explicit LockedVertices(std::vector<uint8_t> locked) : locked_(std::move(locked)) {}
  std::string name() const override { return "locked-vertices"; }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces&) const override {
    if (locked_.empty()) return true;
    if (locked_[c.vt]) return false;
    return !locked_[c.vs] || c.position == mesh.position(c.vs);
  }

 private:
  std::vector<uint8_t> locked_;
};

// Counts the live vertices of each connected component; components never merge or split
// under legal collapses, so the counts only go down by one per collapse.
class ComponentMinimum : public ConstraintModule {
 public:
  explicit ComponentMinimum(std::shared_ptr<const std::vector<uint32_t>> components)
      : given_(std::move(components)) {}
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
  }
  bool allows(const CollapseMesh&, const CollapseCandidate& c, const EdgeFaces&) const override {
    const uint32_t comp = component_[c.vs];
    return count_[comp] > (closed_[comp] ? 4u : 3u);
  }
  void collapsed(const CollapseMesh&, const CollapseCandidate& c) override {
    --count_[component_[c.vs]];
  }

 private:
  std::shared_ptr<const std::vector<uint32_t>> given_;
  std::vector<uint32_t> found_;
  const uint32_t* component_ = nullptr;  // per vertex: given_'s or found_'s
  std::vector<uint32_t> count_;
  std::vector<uint8_t> closed_;
};

class BoundaryRule : public ConstraintModule {
 public:
  std::string name() const override { return "boundary"; }
  bool topological() const override { return true; }
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
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces& edge) const override {
    bool ok = true;
    mesh.for_each_common_neighbor(c.vs, c.vt, [&](VertexId common) {
      if (common != edge.left_apex && common != edge.right_apex) ok = false;
    });
    return ok;
  }
};

// Rejects a collapse after which a face around vs or vt folds (face_fold.h).
class FaceGeometry : public ConstraintModule {
 public:
  std::string name() const override { return "face-geometry"; }
  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces& edge) const override {
    for (VertexId moved : {c.vs, c.vt}) {
      for (FaceId f : mesh.faces_of(moved)) {
        if (f == edge.left || f == edge.right) continue;
        const Triangle& t = mesh.face(f);
        const Vec3& p0 = mesh.position(t[0]);
        const Vec3& p1 = mesh.position(t[1]);
        const Vec3& p2 = mesh.position(t[2]);
        const int k = corner_of(t, moved);
        if (face_folds(p0, p1, p2, k == 0 ? c.position : p0, k == 1 ? c.position : p1,
                       k == 2 ? c.position : p2))
          return false;
      }
    }
    return true;
  }
};

}  // namespace

std::vector<std::unique_ptr<ConstraintModule>> standard_constraints(
    const std::vector<uint8_t>& locked, std::shared_ptr<const std::vector<uint32_t>> components) {
  std::vector<std::unique_ptr<ConstraintModule>> modules;
  modules.push_back(std::make_unique<LockedVertices>(locked));
  modules.push_back(std::make_unique<ComponentMinimum>(std::move(components)));
  modules.push_back(std::make_unique<BoundaryRule>());
  modules.push_back(std::make_unique<LinkCondition>());
  modules.push_back(std::make_unique<FaceGeometry>());
  return modules;
}

}  // namespace parapm
