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

namespace {
std::vector<Vec3f> finite_points(const std::vector<Vec3f>& points, std::vector<int>& index) {
  std::vector<Vec3f> out;
  for (size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) {
      index.push_back(static_cast<int>(i));
      out.push_back(points[i]);
    }
  return out;
}
}  // namespace

CloudNeighbours::CloudNeighbours(const std::vector<Vec3f>& points) : tree_(finite_points(points, cloud_index_)) {}

void CloudNeighbours::within(const Vec3f& q, float r2, std::vector<std::pair<float, int>>& out, bool sorted) const {
  tree_.within(q, r2, out, sorted);
  for (auto& e : out) e.second = cloud_index_[static_cast<size_t>(e.second)];
}

}  // namespace pb::local
