#include "parallel/collapse_merge.h"

#include <queue>
#include <string>
#include <utility>

#include "util/error.h"

namespace parapm {

std::vector<CollapseRecord> merge_by_cost(std::vector<std::vector<CollapseRecord>> lists) {
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
  std::vector<CollapseRecord> merged;
  merged.reserve(total);
  while (!heads.empty()) {
    const uint32_t i = heads.top().list;
    heads.pop();
    merged.push_back(std::move(lists[i][next[i]]));
    if (++next[i] < lists[i].size()) heads.push({lists[i][next[i]].cost, i});
  }
  return merged;
}

ReplayReport replay_collapses(CollapseMesh& mesh, const std::vector<CollapseRecord>& records,
                              PriorityModule* priority) {
  ReplayReport report;
  for (size_t i = 0; i < records.size(); ++i) {
    const CollapseRecord& r = records[i];
    auto fail = [&](const std::string& what) {
      throw_internal("replay: collapse " + std::to_string(i) + " (" + std::to_string(r.vs) + ", " +
                     std::to_string(r.vt) + ") " + what);
    };
    if (r.vs >= mesh.vertex_capacity() || r.vt >= mesh.vertex_capacity() ||
        !mesh.vertex_alive(r.vs) || !mesh.vertex_alive(r.vt))
      fail("names a vertex that is not in the mesh");
    const EdgeFaces edge = mesh.edge_faces(r.vs, r.vt);
    if (edge.left != r.fl || edge.right != r.fr || edge.left_apex != r.vl ||
        edge.right_apex != r.vr)
      fail("does not find the faces its subset saw");
    mesh.collapse(r.vs, r.vt, r.position, edge);
    if (priority) {
      CollapseCandidate done;
      done.vs = r.vs;
      done.vt = r.vt;
      done.position = r.position;
      done.cost = r.cost;
      done.error = r.error;
      priority->collapsed(mesh, done, edge);
      if (done.changed_wedges != r.changed_wedges || done.changed_values != r.changed_values)
        ++report.attribute_mismatches;
    }
    ++report.collapses;
  }
  return report;
}

}  // namespace parapm
