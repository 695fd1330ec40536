// Shared by the partitioning algorithms (not part of the public interface): the vertex graph,
// a bucket queue keyed by small integers (degrees), and the face rule.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/mesh.h"
#include "partition/partition.h"
#include "util/zeroed_array.h"

namespace parapm::partition_detail {

// The mesh's edge graph in compressed rows: the neighbours of v are
// neighbours[offsets[v] .. offsets[v + 1]), each once, in order of first appearance in the
// faces. Isolated vertices have none. 8 bytes per vertex + 4 bytes per directed edge; by faces,
// 8 more per vertex and 12 per face for the face lists, and the greedy's 8 per face.
struct VertexGraph {
  std::vector<size_t> offsets;  // vertex_count + 1
  std::vector<uint32_t> neighbours;
  // What a vertex counts for in its subset's share: 1 (Balance::kVertices) or its number of
  // faces (Balance::kFaces). Set by partition_mesh.
  std::vector<uint32_t> weight;
  // Balance::kFaces only (else empty): the faces of v are face_ids[face_offsets[v] ..
  // face_offsets[v + 1]), for the greedy algorithm to count the faces a subset will own (two
  // corners or more in it) rather than their corners (faces_of).
  std::vector<size_t> face_offsets;
  std::vector<uint32_t> face_ids;
  uint32_t face_count = 0;

  uint32_t vertex_count() const { return uint32_t(offsets.size() - 1); }
  uint32_t degree(uint32_t v) const { return uint32_t(offsets[v + 1] - offsets[v]); }
  std::span<const uint32_t> neighbours_of(uint32_t v) const {
    return {neighbours.data() + offsets[v], neighbours.data() + offsets[v + 1]};
  }
  uint32_t max_degree() const;
  bool has_faces() const { return !face_offsets.empty(); }
  std::span<const uint32_t> faces_of(uint32_t v) const {
    return {face_ids.data() + face_offsets[v], face_ids.data() + face_offsets[v + 1]};
  }
};

// O(F + V). Error(kInvalidInput) when a face corner is out of range; repeated corners are
// ignored (no self loops).
VertexGraph build_vertex_graph(const Mesh& mesh);
// The same graph built in `loops`' chunks, with each vertex's faces (face_offsets, face_ids,
// face_count) when `with_faces`.
VertexGraph build_vertex_graph(const Mesh& mesh, ChunkedLoops& loops, bool with_faces);

// The edges between subsets, and per subset its connected pieces (partition_metrics.cpp).
struct CutShape {
  uint64_t cut_edges = 0;
  std::vector<uint32_t> components;  // per subset
};
CutShape cut_shape(const VertexGraph& graph, const std::vector<uint32_t>& vertex_subset,
                   uint32_t p);

// Items 0..n-1 with integer keys 0..max_key, each in at most once. Insert, remove and changing
// a key are O(1); pop_min scans up from the lowest key that may be occupied. Equal keys pop in
// insertion order (a key change counts as a new insertion), so the order is deterministic.
// The per-item arrays are zeroed pages: a queue costs the pages of the items it holds.
class BucketQueue {
 public:
  BucketQueue(uint32_t items, uint32_t max_key);
  bool empty() const { return size_ == 0; }
  bool contains(uint32_t item) const { return key_plus_one_[item] != 0; }
  void insert(uint32_t item, uint32_t key);
  void remove(uint32_t item);
  void set_key(uint32_t item, uint32_t key) {
    remove(item);
    insert(item, key);
  }
  uint32_t min();  // the item pop_min would return; kNoId when empty
  uint32_t pop_min();

 private:
  std::vector<uint32_t> head_, tail_;  // per key
  // Per item: its neighbours in its key's list (kNoId at an end), valid while it is in the
  // queue, and its key + 1 (0 when absent).
  ZeroedArray<uint32_t> next_, prev_, key_plus_one_;
  uint32_t min_key_ = 0;  // no occupied key is below it
  size_t size_ = 0;
};

// Vertices sorted by degree (stable: ties by id), vertices of degree 0 last: isolated vertices
// are never chosen to start a subset while a vertex with edges is free. The result's pages are
// touched in `loops`' chunks.
std::vector<uint32_t> vertices_by_degree(const VertexGraph& graph, ChunkedLoops& loops);

// The start vertex of the first subset: among the vertices of minimal (non-zero) degree, the
// (seed mod count)-th in id order; where fewer than `candidates` have it, the vertices of the
// next degrees join them, a whole degree at a time, until there are that many (by degree, then
// id). The greedy algorithm asks for kStartCandidates, the BFS baseline for 1 (its quarters of
// a grid start at its corners).
inline constexpr size_t kStartCandidates = 16;
uint32_t first_start_vertex(const VertexGraph& graph, const std::vector<uint32_t>& by_degree,
                            uint64_t seed, size_t candidates);

// Fills partition.face_subset from partition.vertex_subset (the rule in partition.h).
void assign_faces(const Mesh& mesh, Partition& partition, ChunkedLoops& loops);

// Shares of `total` proportional to the weights (equal when empty), by largest remainder.
std::vector<uint64_t> share_targets(uint64_t total, uint32_t p, const std::vector<double>& weights);

// `targets` are in units of VertexGraph::weight: a subset is grown until its vertices' weights
// reach its target (overshooting by less than one vertex's weight), the last takes the rest.
// The greedy runs on the calling thread; its arrays' pages are touched in `loops`' chunks.
Partition greedy_partition(const VertexGraph& graph, const std::vector<uint64_t>& targets,
                           uint64_t seed, ChunkedLoops& loops);
Partition bfs_partition(const VertexGraph& graph, const std::vector<uint64_t>& targets,
                        uint64_t seed);
// Moves boundary vertices and stray components to cut fewer edges while every subset stays
// within [0.97, 1.03] x its target (refine_partition.cpp).
void refine_partition(const VertexGraph& graph, const std::vector<uint64_t>& targets,
                      Partition& partition);

}  // namespace parapm::partition_detail
