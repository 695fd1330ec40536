#include "parallel/collapse_merge.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <queue>
#include <string>
#include <utility>

#include "util/clock.h"
#include "util/error.h"
#include "util/job_pool.h"

namespace parapm {

std::vector<CollapseRecord> merge_by_cost(std::vector<std::vector<CollapseRecord>> lists) {
  std::vector<const CollapseRecord*> order;
  append_merge_order(lists, order);
  std::vector<CollapseRecord> merged;
  merged.reserve(order.size());
  for (const CollapseRecord* r : order) merged.push_back(*r);
  return merged;
}

void append_merge_order(const std::vector<std::vector<CollapseRecord>>& lists,
                        std::vector<const CollapseRecord*>& out) {
  struct Head {
    double cost;
    uint32_t list;
  };
  struct Later {  // min-queue on (cost, list)
    bool operator()(const Head& x, const Head& y) const {
      if (x.cost != y.cost) return x.cost > y.cost;
      return x.list > y.list;
    }
  };
  size_t total = 0;
  std::priority_queue<Head, std::vector<Head>, Later> heads;
  for (uint32_t i = 0; i < lists.size(); ++i) {
    total += lists[i].size();
    if (!lists[i].empty()) heads.push({lists[i][0].cost, i});
  }
  std::vector<size_t> next(lists.size(), 0);
  out.reserve(out.size() + total);
  while (!heads.empty()) {
    const uint32_t i = heads.top().list;
    heads.pop();
    out.push_back(&lists[i][next[i]]);
    if (++next[i] < lists[i].size()) heads.push({lists[i][next[i]].cost, i});
  }
}

namespace {

// The corner wedges a collapse of the present mesh records (Simplifier::perform): fl's
// corners from vs, fr's from vt; kNoId for a missing face or a mesh without wedges.
std::array<WedgeId, 6> corner_wedges_of(const CollapseMesh& mesh, const CollapseRecord& r) {
  std::array<WedgeId, 6> out{kNoId, kNoId, kNoId, kNoId, kNoId, kNoId};
  if (!mesh.has_wedges()) return out;
  auto corners = [&](FaceId f, VertexId first, int slot) {
    if (f == kNoId) return;
    const int k = corner_of(mesh.face(f), first);
    const auto& w = mesh.corner_wedges(f);
    for (int i = 0; i < 3; ++i) out[slot + i] = w[(k + i) % 3];
  };
  corners(r.fl, r.vs, 0);
  corners(r.fr, r.vt, 3);
  return out;
}

// Whether w is the wedge of a corner at v (a collapse changes only wedges around vs, which
// after it holds the corners of vs and vt).
bool is_corner_wedge_at(const CollapseMesh& mesh, VertexId v, WedgeId w) {
  for (FaceId f : mesh.faces_of(v))
    if (mesh.corner_wedges(f)[corner_of(mesh.face(f), v)] == w) return true;
  return false;
}

// Whether every vertex adjacent to both vs and vt is an apex of the edge (the link condition:
// otherwise the collapse leaves a non-manifold mesh). Reads the two vertices' faces only, no
// scratch marks: subsets replay side by side (replay_subsets).
bool link_condition_holds(const CollapseMesh& mesh, VertexId vs, VertexId vt,
                          const EdgeFaces& edge) {
  thread_local std::vector<VertexId> around_vs;
  around_vs.clear();
  for (FaceId f : mesh.faces_of(vs))
    for (VertexId n : mesh.face(f))
      if (n != vs && n != vt) around_vs.push_back(n);
  for (FaceId f : mesh.faces_of(vt))
    for (VertexId n : mesh.face(f))
      if (n != vs && n != vt && n != edge.left_apex && n != edge.right_apex &&
          std::find(around_vs.begin(), around_vs.end(), n) != around_vs.end())
        return false;
  return true;
}

// Checks record r (the index-th of its list) against the present mesh, then performs it;
// returns the faces it removed.
// With `subset`, first that it keeps the subset rule there: vs, vt and every vertex adjacent to
// either are owned by `subset` (so that it reads and changes that subset's part of the mesh
// only, before anything else of it is read).
EdgeFaces check_and_collapse(CollapseMesh& mesh, CollapseRecord& r, size_t index,
                             const std::vector<uint32_t>* vertex_subset, uint32_t subset,
                             CollapseMesh::RemovedCounts* counted) {
  auto fail = [&](const std::string& what) {
    throw_invalid("replay: collapse " + std::to_string(index) +
                  (vertex_subset ? " of subset " + std::to_string(subset) : std::string()) + " (" +
                  std::to_string(r.vs) + ", " + std::to_string(r.vt) + ") " + what);
  };
  // Records may come from a worker over the network: everything the collapse and the PM
  // builder index is checked against the present mesh before the mesh changes.
  if (r.vs >= mesh.vertex_capacity() || r.vt >= mesh.vertex_capacity() || r.vs == r.vt)
    fail("names a vertex that is not in the mesh");
  if (vertex_subset) {
    auto own = [&](VertexId v) { return (*vertex_subset)[v] == subset; };
    if (!own(r.vs) || !own(r.vt)) fail("names a vertex its subset does not own");
    for (VertexId end : {r.vs, r.vt})
      for (FaceId f : mesh.faces_of(end))
        for (VertexId n : mesh.face(f))
          if (!own(n)) fail("breaks the subset rule (a neighbour of another subset)");
  }
  if (!mesh.vertex_alive(r.vs) || !mesh.vertex_alive(r.vt))
    fail("names a vertex that is not in the mesh");
  const EdgeFaces edge = mesh.edge_faces(r.vs, r.vt);
  if ((edge.left == kNoId && edge.right == kNoId) || edge.left != r.fl || edge.right != r.fr)
    fail("does not find the faces its subset saw");
  if (r.to_complete) {
    r.vl = edge.left_apex;
    r.vr = edge.right_apex;
    r.corner_wedges = corner_wedges_of(mesh, r);
    r.vs_position = mesh.position(r.vs);
    r.vt_position = mesh.position(r.vt);
    r.to_complete = false;
  } else if (edge.left_apex != r.vl || edge.right_apex != r.vr) {
    fail("does not find the apexes its subset saw");
  } else if (r.corner_wedges != corner_wedges_of(mesh, r)) {
    fail("names other corner wedges");
  } else if (r.vs_position != mesh.position(r.vs) || r.vt_position != mesh.position(r.vt)) {
    fail("does not start where the mesh has its vertices");
  }
  if (!link_condition_holds(mesh, r.vs, r.vt, edge)) fail("breaks the link condition");
  for (WedgeId w : r.changed_wedges)
    if (!mesh.has_wedges() ||
        !(is_corner_wedge_at(mesh, r.vs, w) || is_corner_wedge_at(mesh, r.vt, w)))
      fail("changes a wedge not around its vertices");
  mesh.collapse(r.vs, r.vt, r.position, edge, counted);
  return edge;
}

}  // namespace

ReplayReport replay_collapses(CollapseMesh& mesh, std::vector<CollapseRecord>& records,
                              PriorityModule* priority) {
  ReplayReport report;
  for (size_t i = 0; i < records.size(); ++i) {
    CollapseRecord& r = records[i];
    const EdgeFaces edge = check_and_collapse(mesh, r, i, nullptr, 0, nullptr);
    if (priority) {
      CollapseCandidate done;
      done.vs = r.vs;
      done.vt = r.vt;
      done.position = r.position;
      done.cost = r.cost;
      done.error = r.error;
      done.vs_before = r.vs_position;
      priority->collapsed(mesh, done, edge);
      if (done.changed_wedges != r.changed_wedges || done.changed_values != r.changed_values)
        ++report.attribute_mismatches;
    }
    ++report.collapses;
  }
  return report;
}

ReplayReport replay_subsets(CollapseMesh& mesh, std::vector<std::vector<CollapseRecord>>& lists,
                            const std::vector<uint32_t>& vertex_subset, unsigned threads,
                            const std::function<void()>& beside) {
  if (vertex_subset.size() != mesh.vertex_capacity())
    throw_internal("replay_subsets: the vertex subsets do not cover the mesh");
  std::vector<CollapseMesh::RemovedCounts> removed(lists.size());
  std::vector<double> seconds(lists.size(), 0);
  const size_t tasks = lists.size() + (beside ? 1 : 0);
  run_jobs(tasks, threads, [&](size_t i) {
    if (i == lists.size()) return beside();
    const auto start = std::chrono::steady_clock::now();
    for (size_t k = 0; k < lists[i].size(); ++k)
      check_and_collapse(mesh, lists[i][k], k, &vertex_subset, uint32_t(i), &removed[i]);
    seconds[i] = seconds_since(start);
  });
  ReplayReport report;
  for (size_t i = 0; i < lists.size(); ++i) {
    mesh.count_removed(removed[i]);
    report.collapses += lists[i].size();
    report.slowest_seconds = std::max(report.slowest_seconds, seconds[i]);
  }
  return report;
}

}  // namespace parapm
