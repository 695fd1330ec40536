// The measures of a partition that the thesis reports (METHOD.md section 3): time, spread of
// the subset sizes in faces, the biggest subset B (it bounds the parallel time), the cut, and
// how many connected pieces each subset is made of.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mesh/mesh.h"
#include "partition/partition.h"

namespace parapm {

struct PartitionMetrics {
  uint32_t p = 0;
  std::string algorithm;
  double seconds = 0;                  // as given by the caller (partition_mesh's run time)
  std::vector<uint64_t> subset_faces;  // faces per subset (Partition::face_subset)
  double stddev_faces = 0;             // population standard deviation of subset_faces
  uint64_t biggest_faces = 0;          // B = max of subset_faces
  // The ideal face count of the biggest subset: faces * weight_b / sum of weights (faces / p
  // for equal weights). B / ideal_faces is the balance; 1 is perfect.
  double ideal_faces = 0;
  uint64_t cut_faces = 0;  // faces whose vertices are not all in one subset
  uint64_t cut_edges = 0;  // edges whose two ends are in different subsets
  // Per subset, its connected components through edges inside the subset (an isolated vertex
  // is one; an empty subset has 0).
  std::vector<uint32_t> components;
};

// O(F + V). Error(kInvalidInput) when the partition does not fit the mesh (sizes, subset ids
// out of range) or options.weights is neither empty nor of size partition.subsets.
PartitionMetrics partition_metrics(const Mesh& mesh, const Partition& partition,
                                   const PartitionOptions& options = {}, double seconds = 0);

}  // namespace parapm
