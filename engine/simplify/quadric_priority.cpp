// Quadric error metric priority (Garland & Heckbert, SIGGRAPH 97), with the boundary planes of
// their section 6.1 and the placement fallback of Hoppe 99 (best of the two ends and the
// midpoint when the optimum is ill-conditioned or lands far from the edge).
#include "simplify/quadric_priority.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "simplify/back_to_back.h"
#include "simplify/vec_math.h"
#include "util/error.h"
#include "util/fresh_pages.h"

namespace parapm {
namespace {

Vec3 normal_of(const CollapseMesh& mesh, FaceId f) {
  const Triangle& t = mesh.face(f);
  return triangle_normal(mesh.position(t[0]), mesh.position(t[1]), mesh.position(t[2]));
}

// The error a collapse of cost `cost` under q records: the root mean squared distance to q's
// planes (q.weight is their area), in model units.
double rms_error(const Quadric& q, double cost) {
  return q.weight > 0 ? std::sqrt(cost / q.weight) : 0.0;
}

// An optimum far from the edge comes from a nearly flat quadric; it folds the mesh.
bool near_edge(const Vec3& p, const Vec3& pa, const Vec3& pb) {
  const Vec3 d = sub(p, scale(add(pa, pb), 0.5));
  return dot(d, d) <= 4.0 * dot(sub(pb, pa), sub(pb, pa));
}

}  // namespace

void QuadricPriority::initialize(const CollapseMesh& mesh) {
  ChunkedLoops plain;
  initialize_in_chunks(mesh, plain);
}

// Face f's plane, weighted by its area, and the boundary planes of its edges (those with no
// face across, and those whose faces lie back to back: back_to_back.h, their planes are one,
// blind to the rim moving within it; counted once, from the face holding a->b with a < b):
// the plane through the edge perpendicular to the face keeps the border from shrinking
// inwards. add(v, q) is called for the face's three corners, then for each such edge k (in
// order) for its two ends. A zero-area face has no plane and adds nothing.
template <typename Add>
void QuadricPriority::face_planes(const CollapseMesh& mesh, const std::vector<FaceId>& twin,
                                  FaceId f, Add add) const {
  const Triangle& t = mesh.face(f);
  const Vec3& p0 = mesh.position(t[0]);
  const Vec3 n2 = triangle_normal(p0, mesh.position(t[1]), mesh.position(t[2]));
  const double len = length(n2);
  if (len == 0) return;
  const Vec3 n = scale(n2, 1.0 / len);
  const Quadric q = Quadric::from_plane(n, -dot(n, p0), 0.5 * len);
  for (VertexId v : t) add(v, q);
  for (int k = 0; k < 3; ++k) {
    const VertexId a = t[k], b = t[(k + 1) % 3];
    const FaceId across = twin[3 * size_t(f) + k];  // the face holding b->a
    if (across != kNoId && (b < a || !back_to_back(n2, normal_of(mesh, across)))) continue;
    const Vec3 e = sub(mesh.position(b), mesh.position(a));
    const Vec3 side = cross(e, n);
    const double side_len = length(side);
    if (side_len == 0) continue;
    const Vec3 m = scale(side, 1.0 / side_len);
    const Quadric qb =
        Quadric::from_plane(m, -dot(m, mesh.position(a)), options_.boundary_weight * dot(e, e));
    add(a, qb);
    add(b, qb);
  }
}

void QuadricPriority::initialize_in_chunks(const CollapseMesh& mesh, ChunkedLoops& loops) {
  assign_touched(quadrics_, mesh.vertex_capacity(), Quadric{}, loops);
  const std::vector<FaceId> twin = mesh.twin_faces(loops);
  if (loops.chunks() > 1 && sum_by_vertex(mesh, twin, loops)) return;
  quadrics_.assign(mesh.vertex_capacity(), Quadric{});
  for (FaceId f = 0; f < mesh.face_capacity(); ++f) {
    if (!mesh.face_alive(f)) continue;
    face_planes(mesh, twin, f, [&](VertexId v, const Quadric& q) { quadrics_[v] += q; });
  }
}

bool QuadricPriority::sum_by_vertex(const CollapseMesh& mesh, const std::vector<FaceId>& twin,
                                    ChunkedLoops& loops) {
  // Each vertex sums its own fan's planes, faces in increasing order (as the mesh lists them
  // when built), so it adds what the pass over the faces adds it, in the same order: the same
  // bits. Each face's planes are found once per corner, three times in all, on every chunk.
  std::atomic<bool> in_order{true};
  loops.run(mesh.vertex_capacity(), [&](size_t begin, size_t end) {
    for (size_t v = begin; v < end; ++v) {
      const std::span<const FaceId> fan = mesh.faces_of(VertexId(v));
      if (!std::is_sorted(fan.begin(), fan.end()) ||
          std::adjacent_find(fan.begin(), fan.end()) != fan.end()) {
        in_order = false;
        return;
      }
      Quadric& sum = quadrics_[v];
      for (FaceId f : fan)
        if (mesh.face_alive(f))
          face_planes(mesh, twin, f, [&](VertexId corner, const Quadric& q) {
            if (corner == v) sum += q;
          });
    }
  });
  return in_order;
}

Vec3 QuadricPriority::place(const Quadric& q, const Vec3& pa, const Vec3& pb) const {
  const Vec3 mid = scale(add(pa, pb), 0.5);
  Vec3 best;
  bool placed = q.minimizer(best) && near_edge(best, pa, pb);
  if (placed && options_.round_to_float) {
    for (double& c : best) c = round_to_float(c);
  }
  if (!placed) {
    best = pa;
    double best_cost = q.evaluate(pa);
    Vec3 mid_placed = mid;
    if (options_.round_to_float)
      for (double& c : mid_placed) c = round_to_float(c);
    for (const Vec3& p : {pb, mid_placed}) {
      const double cost = q.evaluate(p);
      if (cost < best_cost) best_cost = cost, best = p;
    }
  }
  return best;
}

bool QuadricPriority::place_on_constraints(const CollapseMesh& mesh, VertexId a, VertexId b,
                                           const Quadric& q, Quadric& total, Vec3& out,
                                           StarTermsScratch& scratch) const {
  const Vec3& pa = mesh.position(a);
  const Vec3& pb = mesh.position(b);
  const Vec3 o = scale(add(pa, pb), 0.5);  // (the origin of the sums, for precision)
  const double edge_sq = dot(sub(pb, pa), sub(pb, pa));
  PlacementConstraints constraints(o);
  total = q;
  const bool planes = options_.star_planes_weight > 0;
  if (options_.keep_volume || planes) {
    Vec3 g;
    double h;
    Quadric star;
    star_volume(mesh, a, b, o, scratch, g, h, planes ? &star : nullptr);
    if (options_.keep_volume && dot(g, g) > 1e-12 * edge_sq * edge_sq) constraints.require(g, h);
    if (planes) {
      star *= options_.star_planes_weight;
      total += star;
    }
  }
  Vec3 e1, e2;
  if (options_.keep_border && (mesh.is_boundary(a) || mesh.is_boundary(b)) &&
      star_border(mesh, a, b, o, scratch, e1, e2) && dot(e1, e1) > 1e-12 * edge_sq) {
    constraints.require_cross(e1, e2);
  }
  return constraints.minimize(total, out);
}

bool QuadricPriority::evaluate(const CollapseMesh& mesh, VertexId a, VertexId b,
                               CollapseCandidate& out, Costing costing) {
  ++costings_;
  return cost(mesh, a, b, out, costing, star_scratch_);
}

bool QuadricPriority::cost(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                           Costing costing, StarTermsScratch& scratch) const {
  const bool locked_a = !locked_.empty() && locked_[a];
  const bool locked_b = !locked_.empty() && locked_[b];
  if (locked_a && locked_b) return false;
  Quadric q = quadrics_[a];
  q += quadrics_[b];
  out.vs = (locked_b || (!locked_a && b < a)) ? b : a;
  out.vt = out.vs == a ? b : a;
  const Vec3& pa = mesh.position(a);
  const Vec3& pb = mesh.position(b);
  Vec3 kept;
  // Placed at a locked end, or freely: every costing is the one for its collapse.
  out.as_performed = true;
  if (locked_a || locked_b) {
    out.position = mesh.position(out.vs);
  } else if ((!options_.keep_volume && !options_.keep_border) ||
             mesh.live_faces() > options_.free_placement_above_faces) {
    out.position = place(q, pa, pb);
  } else if (costing != Costing::kPerform && q.minimizer(kept)) {
    out.position = kept;  // no placement costs less: a lower bound of the constrained cost
    out.as_performed = false;
  } else if (costing == Costing::kQueue) {
    // A flat or creased star (A singular): the accumulated quadric's least value, a lower
    // bound of the constrained cost as well, without the star's sums.
    out.as_performed = false;
    out.position = scale(add(pa, pb), 0.5);
    out.cost = q.least_value(out.position);
    out.error = rms_error(q, out.cost);
    return true;
  } else {
    // Placed with the star's planes; costed by the accumulated quadric alone, whose free
    // optimum's cost (the queue key) stays a lower bound.
    out.as_performed = costing == Costing::kPerform;
    Quadric total;
    if (place_on_constraints(mesh, a, b, q, total, kept, scratch) && near_edge(kept, pa, pb)) {
      // An end that meets the constraints comes out of the solve up to rounding: a corner
      // stays exactly where it was.
      const double edge_sq = dot(sub(pb, pa), sub(pb, pa));
      for (const Vec3* end : {&pa, &pb})
        if (dot(sub(kept, *end), sub(kept, *end)) <= 1e-18 * edge_sq) kept = *end;
      out.position = kept;
      if (options_.round_to_float)
        for (double& c : out.position) c = round_to_float(c);
    } else {
      out.position = place(total, pa, pb);
    }
  }
  out.cost = std::max(0.0, q.evaluate(out.position));
  out.error = rms_error(q, out.cost);
  return std::isfinite(out.cost);
}

bool QuadricPriority::evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt,
                                    const Vec3* at, CollapseCandidate& out, Costing) {
  ++costings_;
  return cost_seam(mesh, vs, vt, at, out);
}

Quadric QuadricPriority::pair_quadric(VertexId a, VertexId b) const {
  Quadric q = quadrics_[std::min(a, b)];
  q += quadrics_[std::max(a, b)];
  return q;
}

bool QuadricPriority::cost_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                                CollapseCandidate& out) const {
  const Quadric q = pair_quadric(vs, vt);
  out.vs = vs;
  out.vt = vt;
  out.position =
      at ? *at : place(q, mesh.position(std::min(vs, vt)), mesh.position(std::max(vs, vt)));
  out.cost = std::max(0.0, q.evaluate(out.position));
  out.error = rms_error(q, out.cost);
  return std::isfinite(out.cost);
}

void QuadricPriority::evaluate_seam_at(const CollapseMesh&, std::span<const SeamPair> pairs,
                                       std::span<const Vec3> places, Costing,
                                       std::span<SeamCosting> out) {
  costings_ += pairs.size() * places.size();
  cost_seam_at(pairs, places, out, seam_sums_);
}

void QuadricPriority::cost_seam_at(std::span<const SeamPair> pairs, std::span<const Vec3> places,
                                   std::span<SeamCosting> out, std::vector<Quadric>& sums) const {
  // cost_seam's sums and costs, in the same order: the same bits.
  sums.resize(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) sums[i] = pair_quadric(pairs[i].vs, pairs[i].vt);
  for (size_t k = 0; k < places.size(); ++k) {
    double cost = 0, error = 0;
    for (const Quadric& q : sums) {
      const double c = std::max(0.0, q.evaluate(places[k]));
      cost += c;
      error = std::max(error, rms_error(q, c));
    }
    SeamCosting& at = out[k];
    at.candidate = CollapseCandidate{};
    at.candidate.vs = pairs[0].vs;
    at.candidate.vt = pairs[0].vt;
    at.candidate.position = places[k];
    at.candidate.cost = cost;
    at.candidate.error = error;
    at.candidate.seam = true;
    at.placed = std::isfinite(cost);
  }
}

// QuadricPriority::costing_view: the owner's costings with a scratch and a count of its own.
class QuadricCostingView : public PriorityModule {
 public:
  explicit QuadricCostingView(const QuadricPriority& owner) : owner_(owner) {}
  std::string name() const override { return owner_.name(); }
  void initialize(const CollapseMesh&) override {
    throw_internal("a quadric costing view reads its owner's state: it has none to initialise");
  }
  bool evaluate(const CollapseMesh& mesh, VertexId a, VertexId b, CollapseCandidate& out,
                Costing costing) override {
    ++costings_;
    return owner_.cost(mesh, a, b, out, costing, scratch_);
  }
  bool evaluate_seam(const CollapseMesh& mesh, VertexId vs, VertexId vt, const Vec3* at,
                     CollapseCandidate& out, Costing) override {
    ++costings_;
    return owner_.cost_seam(mesh, vs, vt, at, out);
  }
  void evaluate_seam_at(const CollapseMesh&, std::span<const SeamPair> pairs,
                        std::span<const Vec3> places, Costing,
                        std::span<SeamCosting> out) override {
    costings_ += pairs.size() * places.size();
    owner_.cost_seam_at(pairs, places, out, seam_sums_);
  }
  void collapsed(const CollapseMesh&, CollapseCandidate&, const EdgeFaces&) override {
    throw_internal("a quadric costing view performs no collapse");
  }
  uint64_t costings() const override { return costings_; }

 private:
  const QuadricPriority& owner_;
  StarTermsScratch scratch_;
  std::vector<Quadric> seam_sums_;
  uint64_t costings_ = 0;
};

std::unique_ptr<PriorityModule> QuadricPriority::costing_view() const {
  return std::make_unique<QuadricCostingView>(*this);
}

void QuadricPriority::will_cost(VertexId from, std::span<const VertexId> to) const {
  auto prefetch = [&](VertexId v) {
    const char* q = reinterpret_cast<const char*>(&quadrics_[v]);
    __builtin_prefetch(q);
    __builtin_prefetch(q + sizeof(Quadric) - 1);
    if (!locked_.empty()) __builtin_prefetch(&locked_[v]);
  };
  prefetch(from);
  for (VertexId v : to) prefetch(v);
}

void QuadricPriority::collapsed(const CollapseMesh&, CollapseCandidate& done, const EdgeFaces&) {
  quadrics_[done.vs] += quadrics_[done.vt];
}

QuadricState QuadricPriority::export_local(const IdMaps& maps,
                                           const std::vector<uint8_t>* free) const {
  QuadricState state;
  const std::vector<VertexId>& global = *maps.vertex;
  state.vertices.reserve(global.size());
  state.quadrics.reserve(global.size());
  for (size_t i = 0; i < global.size(); ++i) {
    if (free && !(*free)[i]) continue;
    state.vertices.push_back(VertexId(i));
    state.quadrics.push_back(quadrics_[global[i]]);
  }
  return state;
}

void QuadricPriority::import_local(const CollapseMesh& mesh, const QuadricState& state) {
  if (state.vertices.size() != state.quadrics.size())
    throw_invalid("quadric state: vertices and quadrics disagree");
  quadrics_.assign(mesh.vertex_capacity(), Quadric{});
  for (size_t i = 0; i < state.vertices.size(); ++i) {
    if (state.vertices[i] >= quadrics_.size()) throw_invalid("quadric state: vertex out of range");
    quadrics_[state.vertices[i]] = state.quadrics[i];
  }
}

void QuadricPriority::check_records(const std::vector<CollapseRecord>& records, uint32_t subset,
                                    const std::vector<uint32_t>* vertex_subset) const {
  for (size_t i = 0; i < records.size(); ++i) {
    const CollapseRecord& r = records[i];
    for (VertexId v : {r.vs, r.vt}) {
      if (v >= quadrics_.size())
        throw_invalid("collapse " + std::to_string(i) + ": vertex " + std::to_string(v) +
                      " out of range");
      if (vertex_subset && (*vertex_subset)[v] != subset)
        throw_invalid("collapse " + std::to_string(i) + ": vertex " + std::to_string(v) +
                      " is another subset's");
    }
    if (r.vs == r.vt)
      throw_invalid("collapse " + std::to_string(i) + ": vertex " + std::to_string(r.vs) +
                    " into itself");
  }
}

void QuadricPriority::follow_records(const std::vector<CollapseRecord>& records) {
  for (const CollapseRecord& r : records) quadrics_[r.vs] += quadrics_[r.vt];
}

}  // namespace parapm
