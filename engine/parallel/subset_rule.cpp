#include "parallel/subset_rule.h"

#include <algorithm>
#include <atomic>
#include <utility>

namespace parapm {
namespace {

class SubsetConstraint : public ConstraintModule {
 public:
  explicit SubsetConstraint(std::vector<uint8_t> owned) : owned_(std::move(owned)) {}
  std::string name() const override { return "subset"; }
  // Ownership is fixed, the owned count only falls: an edge it vetoes stays vetoed until
  // its star changes.
  bool topological() const override { return true; }

  // Components of the job's mesh: how many owned vertices each holds and whether it also
  // holds halo vertices (then it continues in other subsets).
  void initialize(const CollapseMesh& mesh) override {
    const uint32_t components = connected_components(mesh, component_);
    owned_count_.assign(components, 0);
    continues_.assign(components, 0);
    for (VertexId v = 0; v < mesh.vertex_capacity(); ++v) {
      if (component_[v] == kNoId) continue;
      if (owned_[v])
        ++owned_count_[component_[v]];
      else
        continues_[component_[v]] = 1;
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

class SubsetPriority : public PriorityWrapper {
 public:
  SubsetPriority(PriorityModule& inner, std::vector<uint8_t> free_vertex)
      : PriorityWrapper(inner), free_(std::move(free_vertex)) {}
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    if (!free_[a] || !free_[b]) return false;
    return inner_.evaluate(mesh, a, b, out, costing);
  }
  void evaluate_each(const CollapseMesh& mesh, std::span<EdgeCosting> edges,
                     Costing costing) override {
    evaluate_picked(mesh, edges, costing,
                    [&](const EdgeCosting& e) { return free_[e.a] && free_[e.b]; });
  }
  bool evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                     CollapseCandidate& out, Costing costing) override {
    if (!free_[vs] || !free_[vt]) return false;
    return inner_.evaluate_seam(mesh, vs, vt, at, out, costing);
  }
  // (where a pair is refused, pair by pair: the pairs before it are costed, as ever)
  void evaluate_seam_at(const CollapseMesh& mesh, std::span<const SeamPair> pairs,
                        std::span<const Vec3> places, Costing costing,
                        std::span<SeamCosting> out) override {
    if (std::all_of(pairs.begin(), pairs.end(),
                    [&](const SeamPair& p) { return free_[p.vs] && free_[p.vt]; }))
      inner_.evaluate_seam_at(mesh, pairs, places, costing, out);
    else
      cost_seam_pair_by_pair(mesh, pairs, places, costing, out);
  }

 private:
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

uint64_t removable_faces(const Mesh& mesh, const std::vector<uint8_t>& free) {
  uint64_t removable = 0;
  for (const Triangle& t : mesh.faces) removable += free[t[0]] + free[t[1]] + free[t[2]] >= 2;
  return removable;
}

std::vector<uint8_t> bound_vertices(const CollapseMesh& mesh,
                                    const std::vector<uint32_t>& vertex_subset,
                                    ChunkedLoops* loops) {
  std::vector<uint8_t> bound(mesh.vertex_capacity(), 0);
  // (Chunks may mark a corner they share: the same 1, stored atomically.)
  auto mark = [&](size_t begin, size_t end) {
    for (FaceId f = FaceId(begin); f < end; ++f) {
      if (!mesh.face_alive(f)) continue;
      const Triangle& t = mesh.face(f);
      if (vertex_subset[t[0]] != vertex_subset[t[1]] || vertex_subset[t[1]] != vertex_subset[t[2]])
        for (VertexId v : t) std::atomic_ref<uint8_t>(bound[v]).store(1, std::memory_order_relaxed);
    }
  };
  ChunkedLoops one_thread;
  (loops ? *loops : one_thread).run(mesh.face_capacity(), mark);
  return bound;
}

uint64_t border_faces(const CollapseMesh& mesh, const std::vector<uint8_t>& bound,
                      ChunkedLoops* loops) {
  ChunkedLoops one_thread;
  ChunkedLoops& chunks = loops ? *loops : one_thread;
  std::vector<uint64_t> counts(chunks.ranges(mesh.face_capacity()), 0);
  chunks.run_indexed(mesh.face_capacity(), [&](size_t range, size_t begin, size_t end) {
    uint64_t count = 0;
    for (FaceId f = FaceId(begin); f < end; ++f) {
      if (!mesh.face_alive(f)) continue;
      const Triangle& t = mesh.face(f);
      count += bound[t[0]] + bound[t[1]] + bound[t[2]] >= 2;
    }
    counts[range] = count;
  });
  uint64_t count = 0;
  for (uint64_t c : counts) count += c;
  return count;
}

std::unique_ptr<ConstraintModule> make_subset_constraint(std::vector<uint8_t> owned) {
  return std::make_unique<SubsetConstraint>(std::move(owned));
}

std::unique_ptr<PriorityModule> make_subset_priority(PriorityModule& inner,
                                                     std::vector<uint8_t> free_vertex) {
  return std::make_unique<SubsetPriority>(inner, std::move(free_vertex));
}

}  // namespace parapm
