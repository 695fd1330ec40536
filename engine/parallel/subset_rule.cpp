#include "parallel/subset_rule.h"

#include <utility>

namespace parapm {
namespace {

class SubsetConstraint : public ConstraintModule {
 public:
  explicit SubsetConstraint(std::vector<uint8_t> owned) : owned_(std::move(owned)) {}
  std::string name() const override { return "subset"; }

  // Components of the job's mesh: how many owned vertices each holds and whether it also
  // holds halo vertices (then it continues in other subsets).
  void initialize(const CollapseMesh& mesh) override {
    const size_t n = mesh.vertex_capacity();
    std::vector<VertexId> parent(n);
    for (VertexId v = 0; v < n; ++v) parent[v] = v;
    auto find = [&](VertexId v) {
      while (parent[v] != v) v = parent[v] = parent[parent[v]];
      return v;
    };
    for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
      if (!mesh.face_alive(f)) continue;
      const Triangle& t = mesh.face(f);
      for (int k = 1; k < 3; ++k) {
        const VertexId a = find(t[0]), b = find(t[k]);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
    component_.assign(n, kNoId);
    owned_count_.clear();
    continues_.clear();
    std::vector<uint32_t> index_of_root(n, kNoId);
    for (VertexId v = 0; v < n; ++v) {
      if (!mesh.vertex_alive(v)) continue;
      const VertexId root = find(v);
      if (index_of_root[root] == kNoId) {
        index_of_root[root] = uint32_t(owned_count_.size());
        owned_count_.push_back(0);
        continues_.push_back(0);
      }
      const uint32_t c = index_of_root[root];
      component_[v] = c;
      if (owned_[v])
        ++owned_count_[c];
      else
        continues_[c] = 1;
    }
  }

  bool allows(const CollapseMesh& mesh, const CollapseCandidate& c,
              const EdgeFaces&) const override {
    for (VertexId end : {c.vs, c.vt}) {
      if (!owned_[end]) return false;
      for (FaceId f : mesh.faces_of(end))
        for (VertexId n : mesh.face(f))
          if (!owned_[n]) return false;
    }
    const uint32_t comp = component_[c.vs];
    return !continues_[comp] || owned_count_[comp] > 4;
  }

  void collapsed(const CollapseMesh&, const CollapseCandidate& c) override {
    --owned_count_[component_[c.vs]];
  }

 private:
  std::vector<uint8_t> owned_;
  std::vector<uint32_t> component_;
  std::vector<uint32_t> owned_count_;
  std::vector<uint8_t> continues_;
};

class SubsetPriority : public PriorityModule {
 public:
  SubsetPriority(PriorityModule& inner, std::vector<uint8_t> free_vertex)
      : inner_(inner), free_(std::move(free_vertex)) {}
  std::string name() const override { return inner_.name(); }
  void initialize(const CollapseMesh& mesh) override { inner_.initialize(mesh); }
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b,
                CollapseCandidate& out) const override {
    if (!free_[a] || !free_[b]) return false;
    return inner_.evaluate(mesh, a, b, out);
  }
  void collapsed(const CollapseMesh& mesh, CollapseCandidate& done,
                 const EdgeFaces& edge) override {
    inner_.collapsed(mesh, done, edge);
  }

 private:
  PriorityModule& inner_;
  std::vector<uint8_t> free_;
};

}  // namespace

std::vector<uint8_t> free_vertices(const Mesh& mesh, const std::vector<uint8_t>& owned) {
  std::vector<uint8_t> result(owned);
  for (const Triangle& t : mesh.faces) {
    const bool all_owned = owned[t[0]] && owned[t[1]] && owned[t[2]];
    if (!all_owned)
      for (VertexId v : t) result[v] = 0;
  }
  return result;
}

std::unique_ptr<ConstraintModule> make_subset_constraint(std::vector<uint8_t> owned) {
  return std::make_unique<SubsetConstraint>(std::move(owned));
}

std::unique_ptr<PriorityModule> make_subset_priority(PriorityModule& inner,
                                                     std::vector<uint8_t> free_vertex) {
  return std::make_unique<SubsetPriority>(inner, std::move(free_vertex));
}

}  // namespace parapm
