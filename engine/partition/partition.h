// Mesh partitioning: splits the vertices of a mesh into p subsets of prescribed relative sizes
// with few cut edges, so that p workers can each simplify one subset (METHOD.md section 3).
// Every face is given to exactly one subset (see face_subset below).
//
// Algorithms (PartitionOptions::algorithm):
//  - "greedy": Ciarlet & Lamour's greedy algorithm G (greedy_partition.cpp), O(|E|).
//  - "bfs":    the intuitive baseline: p spread-out seeds grown round-robin by breadth-first
//              search (bfs_partition.cpp), O(p |V| + |E|) (seeding dominates for large p).
// Both are deterministic for a given mesh, p, weights and seed (no hashing, no threads), and
// handle meshes with boundaries, several connected components and isolated vertices.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "util/chunked_loops.h"

namespace parapm {

inline constexpr uint32_t kMaxPartitionSubsets = 256;

// What the subsets' shares count. The workers' work grows with faces, and the balance
// bound is on faces, so faces is the default: the greedy algorithm counts the faces each
// subset will own (greedy_partition.cpp), the BFS baseline a vertex's faces (each face once at
// each of its three corners). Vertex counts are the thesis' original measure; they drift from
// face counts where vertices have few faces (meshes that the repair step cut into many
// pieces). By faces, shares of a face or two (p above about half the vertex count) can leave
// the last greedy subsets without a vertex (the parallel build's default keeps 2000 faces per
// subset: ParallelOptions::min_subset_faces).
enum class Balance { kFaces, kVertices };

struct PartitionOptions {
  std::string algorithm = "greedy";  // "greedy" or "bfs"
  // Relative size of each subset (worker capacity): empty means equal, otherwise exactly p
  // positive finite values. Only ratios matter.
  std::vector<double> weights;
  // Picks the start vertex among the vertices of minimal degree: the (seed mod count)-th of
  // them in id order (for the greedy algorithm, where fewer than 16 have the minimal degree,
  // the vertices of the next degrees join them, after them). Different seeds give different,
  // equally valid partitions.
  uint64_t seed = 1;
  Balance balance = Balance::kFaces;
  // After the algorithm: move boundary vertices and stray components to cut fewer edges,
  // within the balance bound (refine_partition.cpp).
  bool refine = false;
  // Where the graph's construction, the faces' assignment and the first writes to the greedy's
  // arrays run in chunks side by side (the same partition); null: on the calling thread.
  ChunkedLoops* loops = nullptr;
};

struct Partition {
  std::vector<uint32_t> vertex_subset;  // per vertex, its subset in [0, subsets)
  // Per face, the subset that simplifies it: the subset owning the majority (2 or 3) of its
  // vertices; a face whose three vertices are in three subsets goes to the smallest of them.
  std::vector<uint32_t> face_subset;
  uint32_t subsets = 0;  // p
};

// The number of vertices each subset gets: proportional to the weights (equal when empty),
// rounded by largest remainder (ties to the lower subset) so that they sum to `vertices`.
// Throws Error(kInvalidInput) for p outside [1, 256] or bad weights (as partition_mesh).
std::vector<uint32_t> partition_targets(uint32_t vertices, uint32_t p,
                                        const std::vector<double>& weights);

// Partitions `mesh` (any mesh whose faces index existing vertices; a repaired one in practice)
// into p subsets. Subset i gets exactly partition_targets(...)[i] vertices.
// Errors, Error(kInvalidInput): p outside [1, 256]; p larger than the vertex count (every
// subset must be able to hold a vertex; with unequal weights a subset whose share rounds to
// 0 vertices is allowed and stays empty); weights neither empty nor p positive finite
// values; an unknown algorithm; a face corner out of range.
Partition partition_mesh(const Mesh& mesh, uint32_t p, const PartitionOptions& options = {});

namespace partition_detail {
struct VertexGraph;
}

// A mesh's partition graph, built once for several partitions of the same mesh (other seeds
// or p): draw(p, options) gives what partition_mesh(mesh, p, options) gives, the balance being
// the one built for. Holds a reference to `mesh`, which must outlive it; draw() may run on
// several threads at once (each with loops of its own, or none).
class PartitionGraph {
 public:
  // Builds the graph in `loops`' chunks (null: on the calling thread). Error(kInvalidInput)
  // as partition_mesh: too many vertices, a face corner out of range.
  PartitionGraph(const Mesh& mesh, Balance balance, ChunkedLoops* loops = nullptr);
  ~PartitionGraph();
  PartitionGraph(const PartitionGraph&) = delete;
  PartitionGraph& operator=(const PartitionGraph&) = delete;

  // Error(kInvalidInput) as partition_mesh, and for options.balance other than the graph's.
  Partition draw(uint32_t p, const PartitionOptions& options) const;

 private:
  const Mesh& mesh_;
  Balance balance_;
  std::unique_ptr<const partition_detail::VertexGraph> graph_;
};

}  // namespace parapm
