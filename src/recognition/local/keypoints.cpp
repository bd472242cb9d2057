// Keypoints of the local pipeline: a second, coarser voxel grid (THESIS.md
// "Local pipeline" step 1), on the shared grid (preprocess/voxel_grid.h).
// PCL-free.
#include <cmath>

#include "recognition/local/internal.h"
#include "recognition/preprocess/voxel_grid.h"

namespace pb::local {

std::vector<int> voxel_keypoints(const PointSet& cloud, double voxel_mm) {
  VoxelGridOptions o;
  o.leaf_mm = voxel_mm;
  o.order = VoxelGridOptions::Order::kXYZ;
  return voxel_nearest_points(cloud, o);
}

bool finite_row(const float* row, int dim) {
  for (int i = 0; i < dim; ++i)
    if (!std::isfinite(row[i])) return false;
  return true;
}

}  // namespace pb::local
