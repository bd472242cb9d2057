// Keypoints of the local pipeline: a second, coarser voxel grid (thesis
// 3.1.2, keypoint detection), on the shared grid (preprocess/voxel_grid.h).
// PCL-free.
#include <algorithm>
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

// Clouds of up to this many points are scanned whole for a sorted list
// (KdTree3::within_scanned): at SHOT's supports a query lists a large part
// of them, and the tree visits most of its leaves anyway.
constexpr size_t kScanPoints = 4096;

CloudNeighbours::CloudNeighbours(const std::vector<Vec3f>& points) : tree_(finite_points(points, cloud_index_)) {}

size_t CloudNeighbours::within(const Vec3f& q, float r2, std::vector<std::pair<float, int>>& out, bool sorted,
                               int max_points) const {
  const bool thin = max_points > 0;
  size_t found = 0;
  if (thin) {
    found = tree_.within_thinned(q, r2, max_points, out);  // keep_evenly of the tree-order list
    // (squared distance, tree index) pairs order as the kd-tree's sorted keys
    if (sorted) KdTree3::sort_entries(out);
  } else if (sorted && cloud_index_.size() <= kScanPoints) {
    tree_.within_scanned(q, r2, out);
    found = out.size();
  } else {
    tree_.within(q, r2, out, sorted);
    found = out.size();
  }
  // tree index -> cloud index keeps the order (finite_points keeps it)
  for (auto& e : out) e.second = cloud_index_[static_cast<size_t>(e.second)];
  return found;
}

}  // namespace pb::local
