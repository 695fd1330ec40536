#include "simplify/simplifier.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "simplify/vec_math.h"

namespace parapm {

Simplifier::Simplifier(CollapseMesh& mesh, PriorityModule& priority,
                       std::vector<std::unique_ptr<ConstraintModule>> constraints)
    : mesh_(mesh), priority_(priority), constraints_(std::move(constraints)) {
  queue_.drop_when([this](const Entry& e) { return is_stale(e); });
}

size_t Simplifier::plan_costing(VertexId a, VertexId b, size_t& costings) {
  if (costings == costed_.size()) costed_.emplace_back();
  EdgeCosting& planned = costed_[costings];
  planned.a = a;
  planned.b = b;
  planned.candidate.seam = false;
  ++stats_.evaluations;
  return costings++;
}

void Simplifier::queue_edges_around(const std::vector<VertexId>& vertices,
                                    const CancelToken* cancel) {
  std::vector<uint8_t> listed(mesh_.vertex_capacity(), 0);
  for (VertexId v : vertices)
    if (v < listed.size()) listed[v] = 1;
  // A costly module's costings of single edges are planned and made together
  // (PriorityModule::evaluate_each: on its team, if it has one); seams are costed at once. The
  // queue's order does not depend on the order of its pushes.
  const bool together = priority_.costly();
  size_t costings = 0;
  std::vector<VertexId> ring;
  for (size_t i = 0; i < vertices.size(); ++i) {
    const VertexId v = vertices[i];
    if (v >= listed.size() || !mesh_.vertex_alive(v)) continue;
    if (cancel && (i & 1023) == 0) cancel->check();
    mesh_.neighbors(v, ring);
    for (VertexId u : ring) {
      if (listed[u] && u < v)
        continue;  // an edge between two listed vertices: from its smaller end
      if (together && !seam_edge(v, u)) {
        plan_costing(std::min(v, u), std::max(v, u), costings);
        continue;
      }
      Entry entry;
      if (queue_entry(v, u, entry)) queue_.push(entry);
    }
  }
  if (costings == 0) return;
  priority_.evaluate_each(mesh_, std::span(costed_).first(costings), Costing::kQueue);
  for (const EdgeCosting& c : std::span(costed_).first(costings)) {
    Entry entry;
    if (entry_of_costing(c.a, c.b, c.placed, c.candidate.cost, entry)) queue_.push(entry);
  }
}

void Simplifier::push_edge(VertexId a, VertexId b) {
  Entry entry;
  if (queue_entry(a, b, entry)) queue_.push(entry);
}

bool Simplifier::queue_entry(VertexId a, VertexId b, Entry& entry) {
  if (a > b) std::swap(a, b);
  CollapseCandidate& candidate = queued_;
  candidate.seam = false;
  if (first_queue_seams_ && seam_edge(a, b)) {
    const uint64_t groups = uint64_t(groups_->group[a]) << 32 | groups_->group[b];
    const auto [at, first] = first_queue_seams_->try_emplace(groups);
    if (first) {
      at->second.placed = cost_seam(a, b, candidate, Costing::kQueue);
      at->second.cost = candidate.cost;
    }
    return entry_of_costing(a, b, at->second.placed, at->second.cost, entry);
  }
  const bool placed = cost_edge(a, b, candidate, Costing::kQueue);
  return entry_of_costing(a, b, placed, candidate.cost, entry);
}

bool Simplifier::entry_of_costing(VertexId a, VertexId b, bool placed, double cost, Entry& entry) {
  if (!placed) {
    // Refused (a job's subset rule or cost ceiling, locked ends): once its star changes it is
    // deferred to the end of the queue, not costed at once to be refused again.
    if (defer_) remember_key(a, b, std::numeric_limits<float>::infinity());
    return false;
  }
  entry = Entry::of(key_of(cost, a, b), a, b, version_[a] + version_[b]);
  if (defer_) remember_key(a, b, entry.cost());
  return true;
}

float Simplifier::key_of(double cost, VertexId a, VertexId b) const {
  if (cost != 0) return static_cast<float>(cost);
  const Vec3 d = sub(mesh_.position(b), mesh_.position(a));
  const double smallest = 1 / double(std::numeric_limits<float>::max());  // -1 / it: -FLT_MAX
  return static_cast<float>(-1 / std::max(dot(d, d), smallest));
}

std::array<float*, 2> Simplifier::key_slots(VertexId a, VertexId b) {
  const EdgeFaces edge = mesh_.edge_faces(a, b);
  auto slot = [&](FaceId f, VertexId from) {
    return f == kNoId ? nullptr : &face_keys_[3 * size_t(f) + corner_of(mesh_.face(f), from)];
  };
  return {slot(edge.left, a), slot(edge.right, b)};
}

void Simplifier::remember_key(VertexId a, VertexId b, float key) {
  for (float* slot : key_slots(a, b))
    if (slot) *slot = key;
}

float Simplifier::remembered_key(VertexId a, VertexId b) {
  float key = std::numeric_limits<float>::quiet_NaN();
  for (const float* slot : key_slots(a, b))
    if (slot && !std::isnan(*slot)) key = std::isnan(key) ? *slot : std::min(key, *slot);
  return key;
}

bool Simplifier::deferred_entry(VertexId a, VertexId b, Entry& entry) {
  if (a > b) std::swap(a, b);
  float key = remembered_key(a, b);
  if (std::isnan(key)) return false;
  // Below it: a collapse beside an edge mostly raises its cost (points move into its star),
  // and an edge that comes out too early only costs one costing. A refused edge (infinite)
  // comes out when nothing else is left.
  if (!std::isinf(key)) key -= 0.5f * std::abs(key);
  entry = Entry::of(key, a, b, (version_[a] + version_[b]) | kDeferred);
  ++stats_.deferred;
  return true;
}

bool Simplifier::defer_edge(VertexId a, VertexId b) {
  Entry entry;
  if (!deferred_entry(a, b, entry)) return false;
  queue_.push(entry);
  return true;
}

std::vector<DeferredEdge> Simplifier::deferred_edges() {
  std::vector<DeferredEdge> out;
  if (!defer_) return out;
  queue_.for_each([&](const Entry& e) {
    if (!(e.stamp & kDeferred) || is_stale(e)) return;
    // The key it was deferred from: its faces' remembered keys, which only a costing of the
    // edge itself rewrites (and that would have made this entry current, not deferred).
    const float key = remembered_key(e.a, e.b);
    if (!std::isnan(key)) out.push_back({e.a, e.b, key});
  });
  // An edge deferred twice without an end changing in between is listed once.
  sort_unique_edges(out);
  return out;
}

bool Simplifier::seam_already_queued(VertexId a, VertexId b) {
  if (!queueing_seams_ || !groups_->is_copy(a) || !groups_->is_copy(b)) return false;
  const std::pair<uint32_t, uint32_t> pair = std::minmax(groups_->group[a], groups_->group[b]);
  if (std::find(queued_seams_.begin(), queued_seams_.end(), pair) != queued_seams_.end())
    return true;
  queued_seams_.push_back(pair);
  return false;
}

void Simplifier::reject(VertexId a, VertexId b, FaceId folded) {
  remember_rejected(a, b, folded);
  remember_rejected(b, a, folded);
}

bool Simplifier::topologically_legal(VertexId a, VertexId b) const {
  return topologically_legal(a, b, mesh_.edge_faces(a, b), false);
}

bool Simplifier::topologically_legal(VertexId a, VertexId b, const EdgeFaces& edge,
                                     bool star_local_only) const {
  CollapseCandidate edge_only;
  edge_only.vs = a;
  edge_only.vt = b;
  for (const auto& module : constraints_)
    if (module->topological() && (!star_local_only || module->star_local()) &&
        !module->allows(mesh_, edge_only, edge))
      return false;
  return true;
}

void Simplifier::compact_queue() {
  stats_.stale += queue_.remove_if([this](const Entry& e) { return is_stale(e); });
  compacted_size_ = queue_.size();
  ++stats_.compactions;
  forget_outdated_requeued();
}

void Simplifier::forget_outdated_requeued() {
  std::erase_if(requeued_, [this](const auto& record) {
    return requeued_outdated(record.first, record.second);
  });
}

// Each side lists a vetoed edge at most once, so the lists stay as short as the valence.
void Simplifier::remember_rejected(VertexId v, VertexId other, FaceId folded) {
  if (!rejected_slot_[v]) {
    rejected_lists_.emplace_back();
    rejected_slot_[v] = uint32_t(rejected_lists_.size());
  }
  std::vector<Vetoed>& list = rejected_lists_[rejected_slot_[v] - 1];
  const auto it =
      std::find_if(list.begin(), list.end(), [&](const Vetoed& e) { return e.other == other; });
  if (it == list.end())
    list.push_back({other, folded});
  else
    it->folded = folded;
}

bool Simplifier::take_requeued(const Entry& entry, CollapseCandidate& out) {
  if (!(entry.stamp & kRequeued)) return false;
  const auto it = requeued_.find(edge_key(entry.a, entry.b));
  if (it == requeued_.end()) return false;
  const bool unchanged = !requeued_outdated(it->first, it->second);
  if (unchanged) {
    out = std::move(it->second.candidate);
    ++stats_.requeue_reused;
  }
  requeued_.erase(it);
  return unchanged;
}

bool Simplifier::legal(const CollapseCandidate& candidate, const EdgeFaces& edge,
                       bool topology_checked, bool star_checked, FaceId* folded) const {
  for (const auto& module : constraints_) {
    if ((topology_checked && module->topological()) || (star_checked && module->star_local()))
      continue;
    if (module->allows(mesh_, candidate, edge)) continue;
    if (folded) *folded = module->folded_face();
    return false;
  }
  return true;
}

CollapseRecord Simplifier::perform(CollapseCandidate c, const EdgeFaces& edge) {
  CollapseRecord r;
  r.vs = c.vs;
  r.vt = c.vt;
  r.vl = edge.left_apex;
  r.vr = edge.right_apex;
  r.fl = edge.left;
  r.fr = edge.right;
  r.vs_position = mesh_.position(c.vs);
  r.vt_position = mesh_.position(c.vt);
  r.position = c.position;
  r.cost = c.cost;
  if (mesh_.has_wedges()) {
    // Corner order of the vertex split: fl = (vs, vt, vl), fr = (vt, vs, vr).
    auto corners = [&](FaceId f, VertexId first, int slot) {
      if (f == kNoId) return;
      const int k = corner_of(mesh_.face(f), first);
      const auto& w = mesh_.corner_wedges(f);
      for (int i = 0; i < 3; ++i) r.corner_wedges[slot + i] = w[(k + i) % 3];
    };
    corners(edge.left, c.vs, 0);
    corners(edge.right, c.vt, 3);
  }
  c.vs_before = mesh_.position(c.vs);
  mesh_.collapse(c.vs, c.vt, c.position, edge);
  priority_.collapsed(mesh_, c, edge);
  r.error = static_cast<float>(c.error);
  r.changed_wedges = std::move(c.changed_wedges);
  r.changed_values = std::move(c.changed_values);
  for (const auto& module : constraints_) module->collapsed(mesh_, c);
  return r;
}

void Simplifier::requeue_around(VertexId vs, VertexId vt, const SimplifierLimits& limits) {
  ++version_[vs];
  mesh_.neighbors(vs, ring_);
  priority_.will_cost(vs, ring_);
  // Edges vetoed earlier around the changed star may be legal now: cost them again, after
  // the edges of vs. All are taken off the lists first: a push may veto its edge again, onto
  // the lists (screening).
  for (VertexId end : {vt, vs})
    if (std::vector<Vetoed>* list = rejected_list(end)) list->clear();
  retry_.clear();
  for (VertexId n : ring_) {
    std::vector<Vetoed>* list = rejected_list(n);
    if (!list) continue;
    for (const auto& [other, folded] : *list) {
      if (other == vs || !mesh_.vertex_alive(other)) continue;
      // The edge is pushed once, from this side: forget it on the other side too.
      if (std::vector<Vetoed>* mirror = rejected_list(other))
        std::erase_if(*mirror, [&](const Vetoed& e) { return e.other == n; });
      retry_.push_back({n, other, folded});
    }
    list->clear();
  }
  const bool defer = defer_ && mesh_.live_faces() > limits.defer_above_faces;
  if (screen_) {
    requeue_costly(vs, defer);
    return;
  }
  for (VertexId n : ring_)
    if (!seam_already_queued(vs, n) && !(defer && defer_edge(vs, n))) queue_checked(vs, n, limits);
  for (const auto& [n, other, folded] : retry_) {
    ++stats_.reevaluated;
    queue_checked(n, other, limits, folded);
  }
}

void Simplifier::queue_checked(VertexId a, VertexId b, const SimplifierLimits& limits,
                               FaceId folded) {
  Entry entry;
  if (!queue_entry(a, b, entry)) return;
  // (not within a seam collapse, whose survivors' versions change one after another)
  if (check_when_queued_ && entry.cost() <= last_key_ && !queueing_seams_ &&
      !seam_edge(entry.a, entry.b) && vetoed_when_queued(entry, limits, folded))
    return;
  queue_.push(entry);
}

bool Simplifier::vetoed_when_queued(Entry& entry, const SimplifierLimits& limits, FaceId folded) {
  // run()'s steps for a current entry on top, up to its rules; an edge its pop would drop
  // without a veto (unplaced, gone, over the ceiling) is queued.
  const auto veto = [&](FaceId face) {
    ++stats_.rejected;
    ++stats_.vetoed_when_queued;
    reject(entry.a, entry.b, face);
    return true;
  };
  CollapseCandidate& candidate = checked_;
  bool topology_checked = false;
  if (queued_.as_performed) {  // (queue_entry's costing of this edge, just made)
    candidate = queued_;
  } else {
    // A costing for the collapse (the quadric's constrained placement) costs far more than the
    // rules of the star that read the edge alone, which veto most edges retried at coarse
    // levels: those first, but for an edge a fold vetoed last (its face is tested first, after
    // the costing: the link condition costs more around a hub). Only where that costing is
    // placed (PriorityModule::placed_when_queued_is_placed) and under no ceiling, where its cost
    // is never over it: else the edge would be queued, not vetoed.
    if (folded == kNoId && priority_.placed_when_queued_is_placed() &&
        limits.max_cost == std::numeric_limits<double>::infinity()) {
      const EdgeFaces edge = mesh_.edge_faces(entry.a, entry.b);
      if (edge.left == kNoId && edge.right == kNoId) return false;
      if (!topologically_legal(entry.a, entry.b, edge, true)) return veto(kNoId);
      topology_checked = true;
    }
    candidate.seam = false;
    if (!cost_edge(entry.a, entry.b, candidate, Costing::kPerform)) return false;
  }
  const EdgeFaces edge = mesh_.edge_faces(candidate.vs, candidate.vt);
  if ((edge.left == kNoId && edge.right == kNoId) || candidate.cost > limits.max_cost) return false;
  if (folded != kNoId && collapse_folds_face(mesh_, candidate, edge, folded)) return veto(folded);
  for (const auto& module : constraints_)
    if (module->star_local() && !(topology_checked && module->topological()) &&
        !module->allows(mesh_, candidate, edge))
      return veto(module->folded_face());
  entry.stamp |= kRequeued;
  requeued_[edge_key(entry.a, entry.b)] = {mesh_.star_version(entry.a), mesh_.star_version(entry.b),
                                           candidate};
  return false;
}

// The pushes in requeue_around's order, each edge's costing planned rather than done; then the
// planned costings together; then the pushes in that order: the same queue as costing one
// edge after the other (a costing changes no state a later one reads).
void Simplifier::requeue_costly(VertexId vs, bool defer) {
  planned_.clear();
  size_t costings = 0;
  auto plan = [&](VertexId a, VertexId b) {
    if (a > b) std::swap(a, b);
    Entry entry{};
    if (seam_edge(a, b)) {  // a seam's: costed now, alone
      if (queue_entry(a, b, entry)) planned_.push_back({entry, kNotCosted});
      return;
    }
    planned_.push_back({entry, plan_costing(a, b, costings)});
  };
  for (VertexId n : ring_) {
    if (seam_already_queued(vs, n)) continue;
    Entry entry{};
    if (defer && deferred_entry(vs, n, entry)) {
      planned_.push_back({entry, kNotCosted});
      continue;
    }
    plan(vs, n);
  }
  for (const Retry& retry : retry_) {
    ++stats_.reevaluated;
    // Vetoed once, an edge is often vetoed again (near the legal minimum, thousands are, each
    // star change around them): the rules that need no costing first.
    if (!topologically_legal(retry.a, retry.b)) {
      ++stats_.screened;
      reject(retry.a, retry.b);
      continue;
    }
    plan(retry.a, retry.b);
  }
  priority_.evaluate_each(mesh_, std::span(costed_).first(costings), Costing::kQueue);
  for (PlannedPush& push : planned_) {
    if (push.costing != kNotCosted) {
      const EdgeCosting& c = costed_[push.costing];
      if (!entry_of_costing(c.a, c.b, c.placed, c.candidate.cost, push.entry)) continue;
    }
    queue_.push(push.entry);
  }
}

bool Simplifier::cost_edge(VertexId a, VertexId b, CollapseCandidate& out, Costing costing) {
  out.as_performed = false;  // (the module says when it is)
  if (seam_edge(a, b)) return cost_seam(a, b, out, costing);
  ++stats_.evaluations;
  return priority_.evaluate(mesh_, a, b, out, costing);
}

bool Simplifier::pair_seam(uint32_t from, uint32_t into) {
  seam_pairs_.clear();
  for (VertexId copy : groups_->of(from)) {
    if (!mesh_.vertex_alive(copy)) continue;
    if (seam_pairs_.size() == kMaxSeamCopies) return false;
    // The smallest neighbour in `into`, read off the faces around the copy (by selects, not
    // branches: which corners are in `into` cannot be predicted).
    const uint32_t* group = groups_->group.data();
    VertexId partner = kNoId;
    for (FaceId f : mesh_.faces_of(copy))
      for (VertexId n : mesh_.face(f)) {
        const bool nearer = (n != copy) & (group[n] == into) & (n < partner);
        partner = nearer ? n : partner;
      }
    if (partner == kNoId) return false;
    seam_pairs_.push_back({partner, copy});
  }
  // Copies in parts too small to shrink stay.
  for (const auto& module : constraints_) module->drop_too_small(mesh_, seam_pairs_);
  return !seam_pairs_.empty();
}

bool Simplifier::all_survive(uint32_t into) const {
  for (VertexId copy : groups_->of(into))
    if (mesh_.vertex_alive(copy) && std::none_of(seam_pairs_.begin(), seam_pairs_.end(),
                                                 [&](const SeamPair& p) { return p.vs == copy; }))
      return false;
  return true;
}

bool Simplifier::rings_apart() {
  if (seam_mark_.size() < mesh_.vertex_capacity()) seam_mark_.assign(mesh_.vertex_capacity(), 0);
  if (seam_stamp_ > UINT32_MAX - 2 * kMaxSeamCopies) {
    std::fill(seam_mark_.begin(), seam_mark_.end(), 0);
    seam_stamp_ = 0;
  }
  const uint32_t base = seam_stamp_;
  seam_stamp_ += uint32_t(seam_pairs_.size());
  for (size_t i = 0; i < seam_pairs_.size(); ++i) {
    const uint32_t mine = base + uint32_t(i) + 1;
    for (VertexId end : {seam_pairs_[i].vs, seam_pairs_[i].vt}) {
      mesh_.neighbors(end, seam_ring_);
      seam_ring_.push_back(end);
      for (VertexId v : seam_ring_) {
        if (seam_mark_[v] > base && seam_mark_[v] != mine) return false;
        seam_mark_[v] = mine;
      }
    }
  }
  return true;
}

bool Simplifier::seam_holds_in_turn(const Vec3& place) {
  // The faces around every end: all that the neighbourhood rules read of each collapse, and
  // all the earlier collapses change of it.
  std::vector<FaceId>& faces = seam_faces_;
  faces.clear();
  for (const SeamPair& p : seam_pairs_)
    for (VertexId end : {p.vs, p.vt})
      faces.insert(faces.end(), mesh_.faces_of(end).begin(), mesh_.faces_of(end).end());
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  Mesh local;
  std::vector<std::pair<VertexId, VertexId>> ids;  // (mesh id, local id), sorted by mesh id
  auto local_id = [&](VertexId v) {
    const auto at = std::lower_bound(ids.begin(), ids.end(), std::pair{v, VertexId(0)});
    return at != ids.end() && at->first == v ? at->second : kNoId;
  };
  for (FaceId f : faces)
    for (VertexId v : mesh_.face(f))
      if (local_id(v) == kNoId) {
        ids.insert(std::lower_bound(ids.begin(), ids.end(), std::pair{v, VertexId(0)}),
                   {v, VertexId(local.positions.size())});
        local.positions.push_back(mesh_.position(v));
      }
  for (FaceId f : faces) {
    const Triangle& t = mesh_.face(f);
    local.faces.push_back({local_id(t[0]), local_id(t[1]), local_id(t[2])});
  }
  CollapseMesh trial(local);
  if (seam_rules_.empty()) seam_rules_ = neighbourhood_constraints();
  for (const SeamPair& p : seam_pairs_) {
    CollapseCandidate c;
    c.vs = local_id(p.vs);
    c.vt = local_id(p.vt);
    c.position = place;
    c.seam = true;
    const EdgeFaces edge = trial.edge_faces(c.vs, c.vt);
    for (const auto& rule : seam_rules_)
      if (!rule->allows(trial, c, edge)) return false;
    trial.collapse(c.vs, c.vt, c.position, edge);
  }
  return true;
}

bool Simplifier::cost_seam(VertexId a, VertexId b, CollapseCandidate& out, Costing costing) {
  const uint32_t group_a = groups_->group[a], group_b = groups_->group[b];
  bool found = false;
  std::vector<Vec3>& places = seam_places_;
  for (const auto& [from, into] : {std::pair{group_a, group_b}, std::pair{group_b, group_a}}) {
    if (from == into || !pair_seam(from, into)) continue;
    // Where the survivors are; and when every copy of `into` survives, where the pairs'
    // collapses would each put it (the first's only for a queue key).
    places.assign(1, mesh_.position(seam_pairs_[0].vs));
    if (all_survive(into)) {
      const size_t free_places = costing == Costing::kPerform ? seam_pairs_.size() : 1;
      for (size_t i = 0; i < free_places; ++i) {
        CollapseCandidate c;
        ++stats_.evaluations;
        if (priority_.evaluate_seam(mesh_, seam_pairs_[i].vs, seam_pairs_[i].vt, nullptr, c,
                                    costing) &&
            std::find(places.begin(), places.end(), c.position) == places.end())
          places.push_back(c.position);
      }
    }
    seam_costs_.resize(places.size());
    stats_.evaluations += seam_pairs_.size() * places.size();
    priority_.evaluate_seam_at(mesh_, seam_pairs_, places, costing, seam_costs_);
    for (SeamCosting& at : seam_costs_) {
      if (!at.placed || (found && !(at.candidate.cost < out.cost))) continue;
      out = std::move(at.candidate);
      found = true;
    }
  }
  return found;
}

bool Simplifier::perform_seam(const CollapseCandidate& seam, const SimplifierLimits& limits,
                              std::vector<CollapseRecord>& records) {
  const uint32_t from = groups_->group[seam.vt], into = groups_->group[seam.vs];
  if (!pair_seam(from, into)) return false;
  const std::vector<SeamPair> pairs = seam_pairs_;
  const Vec3 place = seam.position;
  // The survivors move only all together.
  if (place != mesh_.position(pairs[0].vs) && !all_survive(into)) return false;
  // Each collapse legal on the mesh as it is (a veto is remembered on that edge, whose star
  // changing costs the seam again).
  for (const SeamPair& p : pairs) {
    CollapseCandidate c;
    c.vs = p.vs;
    c.vt = p.vt;
    c.position = place;
    c.seam = true;
    if (!legal(c, mesh_.edge_faces(c.vs, c.vt))) {
      reject(c.vs, c.vt);
      return false;
    }
  }
  // Where one collapse can change what another's rules read, they are tried in turn first.
  const bool in_turn = !rings_apart();
  if (in_turn && !seam_holds_in_turn(place)) {
    reject(pairs[0].vs, pairs[0].vt);
    return false;
  }

  size_t done = 0;
  for (; done < pairs.size(); ++done) {
    // Costed on the mesh the earlier collapses left (the records' errors), checked again.
    CollapseCandidate c;
    ++stats_.evaluations;
    const bool placed = priority_.evaluate_seam(mesh_, pairs[done].vs, pairs[done].vt, &place, c,
                                                Costing::kPerform);
    c.seam = true;
    c.cost = seam.cost;  // the records of one seam collapse stay together when merged by cost
    const EdgeFaces edge = mesh_.edge_faces(pairs[done].vs, pairs[done].vt);
    if (!placed || !legal(c, edge)) {
      if (done == 0) return false;
      ++stats_.seams_split;
      break;
    }
    records.push_back(perform(c, edge));
  }
  // The edges around the survivors costed on the mesh the whole seam collapse left, a seam
  // between two groups once (its costing reads the groups, not the copy it is queued on).
  queued_seams_.clear();
  queueing_seams_ = true;
  for (size_t i = 0; i < done; ++i) requeue_around(pairs[i].vs, pairs[i].vt, limits);
  queueing_seams_ = false;
  ++stats_.seam_collapses;
  stats_.seams_in_turn += in_turn;
  return true;
}

void Simplifier::begin_run(const SimplifierLimits& limits) {
  stats_ = {};
  priority_.initialize(mesh_);
  for (const auto& module : constraints_) module->initialize(mesh_);
  version_.assign_zeroed(mesh_.vertex_capacity());
  requeued_.clear();
  rejected_slot_.assign_zeroed(mesh_.vertex_capacity());
  rejected_lists_.clear();
  defer_ = priority_.costly() && limits.defer_above_faces != SIZE_MAX;
  face_keys_.assign(defer_ ? 3 * size_t(mesh_.face_capacity()) : 0,
                    std::numeric_limits<float>::quiet_NaN());
  screen_ = priority_.costly();
  check_when_queued_ = !screen_ && priority_.queue_key_of_ends_only();
  last_key_ = 0;
}

void Simplifier::build_first_queue(const SimplifierLimits& limits, const CancelToken* cancel) {
  // Every undirected edge once. The queue's order does not depend on the order of insertion.
  queue_.clear();
  compacted_size_ = 0;
  // (no collapse before the queue is built: a seam's queue costing, which reads its two groups
  // only, is the same for every edge between them)
  SeamCostings seams;
  first_queue_seams_ = groups_ ? &seams : nullptr;
  struct Forget {
    SeamCostings*& memo;
    ~Forget() { memo = nullptr; }
  } forget{first_queue_seams_};
  if (limits.first_queue_around) {
    queue_edges_around(*limits.first_queue_around, cancel);
  } else {
    const std::vector<DeferredEdge>* hints = defer_ && limits.first_deferred &&
                                                     !limits.first_deferred->empty() &&
                                                     mesh_.live_faces() > limits.defer_above_faces
                                                 ? limits.first_deferred
                                                 : nullptr;
    // From each edge's smaller end. (From the faces, an edge had to be told apart from its
    // twin: a table of every face's twins, built by comparing every two faces around each
    // vertex, took 2% of a small mesh's parallel build, which starts a queue per job.)
    std::vector<VertexId> ring;
    for (VertexId a = 0; a < mesh_.vertex_capacity(); ++a) {
      if (!mesh_.vertex_alive(a)) continue;
      // The first costing of every edge takes a while with the energy: stay cancellable.
      if (cancel && (a & 1023) == 0) cancel->check();
      mesh_.neighbors(a, ring);
      // The hints at a: sorted by (a, b), searched once per vertex, not once per edge.
      const DeferredEdge* hint_first = nullptr;
      const DeferredEdge* hint_end = nullptr;
      if (hints) {
        const auto first =
            std::lower_bound(hints->begin(), hints->end(), DeferredEdge{a, 0, 0}, ByEdge{});
        const auto end = std::lower_bound(first, hints->end(), DeferredEdge{a + 1, 0, 0}, ByEdge{});
        hint_first = hints->data() + (first - hints->begin());
        hint_end = hints->data() + (end - hints->begin());
      }
      for (const VertexId b : ring) {
        if (b < a) continue;
        Entry entry;
        const DeferredEdge* hint =
            std::find_if(hint_first, hint_end, [&](const DeferredEdge& h) { return h.b == b; });
        if (hint != hint_end && !std::isnan(hint->key)) {  // (a NaN key is no key)
          remember_key(a, b, hint->key);
          if (deferred_entry(a, b, entry)) queue_.push(entry);
          continue;
        }
        if (queue_entry(a, b, entry)) queue_.push(entry);
      }
    }
  }
}

std::vector<CollapseRecord> Simplifier::run(const SimplifierLimits& limits,
                                            const ProgressCallback& progress,
                                            const CancelToken* cancel) {
  begin_run(limits);
  build_first_queue(limits, cancel);

  const size_t start_faces = mesh_.live_faces();
  const uint64_t total = start_faces > limits.target_faces ? start_faces - limits.target_faces : 0;
  std::vector<CollapseRecord> records;
  records.reserve(mesh_.live_vertices());
  size_t next_report = 1024;  // records made when progress is next reported
  // The ceiling as a key: keys are floats, and a collapse costing the ceiling exactly may key a
  // rounding above it in double.
  const float key_ceiling = limits.max_cost < double(std::numeric_limits<float>::max())
                                ? static_cast<float>(limits.max_cost)
                                : std::numeric_limits<float>::infinity();
  stats_.stop_reason = "no legal collapse left";

  while (!queue_.empty()) {
    if (mesh_.live_faces() <= limits.target_faces) {
      stats_.stop_reason = "target face count reached";
      break;
    }
    // Lazy deletion leaves stale entries behind (about nine per collapse). Once the queue
    // holds more than two entries per live face (live edges are ~1.5 per face) they are
    // dropped in one sequential pass; amortised, each entry is compacted away at most once.
    // Not again before the queue has doubled since the last pass: a mesh of many tiny pieces holds
    // more current entries than that (3 edges per face for loose triangles), and a pass per pop
    // made it quadratic (the motorbike with --free-copies: 789 s, chair-dupfaces 0.95 s for
    // no collapse at all).
    if (queue_.size() > std::max<size_t>(2 * mesh_.live_faces() + 1024, 2 * compacted_size_))
      compact_queue();
    const Entry entry = queue_.pop();
    if (const Entry* next = queue_.peek()) prefetch_staleness(*next);
    if (is_stale(entry)) {
      ++stats_.stale;
      continue;
    }
    if (entry.cost() > key_ceiling) {  // and so does every entry after it
      queue_.push(entry);              // (deferred_edges() lists what the queue holds)
      stats_.stop_reason = "cost ceiling reached";
      break;
    }
    if (entry.stamp & kDeferred) {  // costed now, back at its true key
      push_edge(entry.a, entry.b);
      continue;
    }
    // The entry is current, so the cost and placement are those of the present mesh; only
    // legality depends on the neighbourhood and is checked now (Decimater: re-check on pop).
    CollapseCandidate candidate;
    // (topological rules are symmetric in the edge's ends: once passed, they hold for vs, vt)
    bool topology_checked = false;
    // (a kept requeued candidate passed every rule when it was requeued, its star as it is now)
    const bool star_checked = take_requeued(entry, candidate);
    if (!star_checked) {
      // Its ends unchanged, a neighbour's collapse may still have broken its link: then no
      // costing (with a costly module).
      topology_checked = screen_;
      if (screen_ && !topologically_legal(entry.a, entry.b)) {
        ++stats_.rejected;
        ++stats_.screened;
        reject(entry.a, entry.b);
        continue;
      }
      if (!cost_edge(entry.a, entry.b, candidate, Costing::kPerform)) continue;
    }
    // A seam collapse's first pair may be another edge than the entry's.
    if (candidate.seam &&
        !(std::minmax(candidate.vs, candidate.vt) == std::minmax(entry.a, entry.b)))
      topology_checked = false;
    const EdgeFaces edge = mesh_.edge_faces(candidate.vs, candidate.vt);
    if (edge.left == kNoId && edge.right == kNoId) {  // a re-costed edge that is gone
      ++stats_.stale;
      continue;
    }
    // (the collapse edits the apexes' face lists: loaded while the rules are checked)
    for (VertexId apex : {edge.left_apex, edge.right_apex})
      if (apex != kNoId) mesh_.prefetch_vertex(apex);
    // Its key was under the ceiling (a float, or a star changed since) but its cost is not:
    // left out of the queue, like an edge refused, until its star changes; its key stays
    // remembered for a deferral.
    if (candidate.cost > limits.max_cost) {
      ++stats_.over_ceiling;
      continue;
    }
    FaceId folded = kNoId;
    if (!legal(candidate, edge, topology_checked, star_checked, &folded)) {
      ++stats_.rejected;
      reject(entry.a, entry.b, folded);
      continue;
    }
    // A key is kept until an end of its edge changes, though collapses beside the edge change
    // its star, and with it the cost (the energy's points move in). A key that has fallen
    // behind lets its edge jump the queue: when the cost now is above the next key, the edge
    // goes back with it (lazy re-evaluation). It comes out again at its true cost, so the
    // loop ends: a requeue changes no state.
    while (!queue_.empty() && is_stale(queue_.top())) {
      queue_.pop();
      ++stats_.stale;
    }
    const Entry now = Entry::of(key_of(candidate.cost, entry.a, entry.b), entry.a, entry.b,
                                entry.stamp | kRequeued);
    if (!queue_.empty() && queue_.top().key < now.key) {
      queue_.push(now);
      ++stats_.requeued;
      // (a seam collapse's costing also reads its other copies' stars and its parts' sizes,
      // which requeued_outdated does not follow: it is costed again)
      if (!candidate.seam)
        requeued_[edge_key(entry.a, entry.b)] = {mesh_.star_version(entry.a),
                                                 mesh_.star_version(entry.b), std::move(candidate)};
      continue;
    }
    last_key_ = now.cost();
    if (candidate.seam) {
      if (!perform_seam(candidate, limits, records)) {
        ++stats_.rejected;
        continue;
      }
    } else {
      records.push_back(perform(candidate, edge));
      requeue_around(candidate.vs, candidate.vt, limits);
    }

    if (records.size() >= next_report) {
      next_report = records.size() + 1024;
      // Progress first: a caller may cancel from its callback (a worker polling its call).
      if (progress) progress(std::min<uint64_t>(start_faces - mesh_.live_faces(), total), total);
      if (cancel) cancel->check();
    }
  }
  stats_.collapses = records.size();
  if (progress) progress(std::min<uint64_t>(start_faces - mesh_.live_faces(), total), total);
  return records;
}

}  // namespace parapm
