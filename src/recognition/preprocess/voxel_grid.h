// The one voxel grid of recognition (PCL-free): scene and view downsampling,
// keypoints of the local pipeline, the PPF model. Cells are
// floor(p / leaf) per axis; non-finite points are skipped. Options choose
// what each caller has always needed:
//  - order of the output cells: pcl::VoxelGrid's (by z index, then y, then
//    x) or by x, then y, then z;
//  - how the cell index is computed: p * (1 / leaf) (pcl::VoxelGrid) or
//    p / leaf (the PPF model's grid), which can differ on cell borders;
//  - what a cell becomes (voxel_downsample): the centroid, with normals
//    averaged and renormalized, curvature averaged, and the pixel of the
//    point nearest the centroid (ties: the smaller pixel); or
//    (voxel_nearest_points) the index of the point nearest the centroid
//    (ties: the lower index).
#pragma once

#include <vector>

#include "recognition/cloud.h"

namespace pb {

struct VoxelGridOptions {
  double leaf_mm = 10.0;
  enum class Order { kZYX, kXYZ } order = Order::kZYX;
  enum class CellIndex { kTimesInverse, kDivide } cell_index = CellIndex::kTimesInverse;
  // voxel_downsample with normals: if > 0, a cell whose summed normals are
  // not longer than this x its point count is dropped (normals cancel out);
  // if 0, such a cell (sum exactly 0) keeps the normal of its first point.
  double drop_cancelled_normals = 0;
  // voxel_downsample with normals: if > 0, a cell's points are clustered by
  // normal (Vidal et al. 2018's sampling for PPF): a point joins the first
  // cluster of its cell (input order) whose first normal is within this
  // angle, else starts one; each cluster becomes one output point (its
  // centroid and mean normal), the cell's clusters in creation order. Keeps
  // both sides of an edge that a plain grid would average away. 0 = off.
  double normal_cluster_deg = 0;
  // The box of the input's finite points (lo x y z, hi x y z; lo > hi if
  // there is none) when the caller has it (the range cut's), else nullptr:
  // the grid computes it. The cells are sized from it.
  const float* box = nullptr;
};

// Centroid per occupied cell. leaf <= 0 or an empty cloud: the input as is.
PointSet voxel_downsample(const PointSet& in, const VoxelGridOptions& opt);
// Index of the point nearest the centroid, per occupied cell.
std::vector<int> voxel_nearest_points(const PointSet& in, const VoxelGridOptions& opt);

// The grid with the smallest leaf (bisection, 30 steps) that leaves at most
// `target` points (PPF model); clouds of at most `target` points are
// voxelized at 0.001 mm (duplicates merged).
PointSet voxel_downsample_to(const PointSet& in, int target, const VoxelGridOptions& base);

}  // namespace pb
