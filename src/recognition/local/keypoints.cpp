// Keypoints of the local pipeline: a second, coarser voxel grid (THESIS.md
// "Local pipeline" step 1), on the shared grid (preprocess/voxel_grid.h).
// PCL-free.
#include <algorithm>
#include <cmath>

#include "recognition/local/internal.h"
#include "recognition/preprocess/voxel_grid.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif

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
// (scan_within): at SHOT's supports a query lists a large part of them, and
// the tree visits most of its leaves anyway.
constexpr size_t kScanPoints = 4096;

CloudNeighbours::CloudNeighbours(const std::vector<Vec3f>& points) : tree_(finite_points(points, cloud_index_)) {
  if (cloud_index_.size() > kScanPoints) return;
  const size_t n = cloud_index_.size(), padded = (n + 3) / 4 * 4;
  xs_.assign(padded, 0.f), ys_.assign(padded, 0.f), zs_.assign(padded, 0.f);
  for (size_t i = 0; i < n; ++i) {
    const Vec3f& p = points[static_cast<size_t>(cloud_index_[i])];
    xs_[i] = p.x(), ys_[i] = p.y(), zs_[i] = p.z();
  }
}

void CloudNeighbours::scan_within(const Vec3f& q, float r2, std::vector<std::pair<float, int>>& out) const {
  out.clear();
  if (!q.allFinite() || !(r2 > 0)) return;  // as KdTree3::within
  const size_t n = cloud_index_.size();
  // The squared distance as the tree's leaves compute it: x^2 + (y^2 + z^2)
  // of the point minus q, four points at a time (SSE2, baseline x86-64).
  size_t i = 0;
#ifdef __SSE2__
  const __m128 qx = _mm_set1_ps(q.x()), qy = _mm_set1_ps(q.y()), qz = _mm_set1_ps(q.z()), bound = _mm_set1_ps(r2);
  alignas(16) float d4[4];
  for (; i + 4 <= n; i += 4) {
    const __m128 dx = _mm_sub_ps(_mm_loadu_ps(&xs_[i]), qx), dy = _mm_sub_ps(_mm_loadu_ps(&ys_[i]), qy),
                 dz = _mm_sub_ps(_mm_loadu_ps(&zs_[i]), qz);
    const __m128 d = _mm_add_ps(_mm_mul_ps(dx, dx), _mm_add_ps(_mm_mul_ps(dy, dy), _mm_mul_ps(dz, dz)));
    int mask = _mm_movemask_ps(_mm_cmplt_ps(d, bound));
    if (mask == 0) continue;
    _mm_store_ps(d4, d);
    for (; mask != 0; mask &= mask - 1) {
      const int k = __builtin_ctz(static_cast<unsigned>(mask));
      out.emplace_back(d4[k], static_cast<int>(i) + k);
    }
  }
#endif
  for (; i < n; ++i) {
    const float dx = xs_[i] - q.x(), dy = ys_[i] - q.y(), dz = zs_[i] - q.z();
    const float d = dx * dx + (dy * dy + dz * dz);
    if (d < r2) out.emplace_back(d, static_cast<int>(i));
  }
  KdTree3::sort_entries(out);  // by (distance, index): the tree's order
}

size_t CloudNeighbours::within(const Vec3f& q, float r2, std::vector<std::pair<float, int>>& out, bool sorted,
                               int max_points) const {
  const bool thin = max_points > 0;
  size_t found = 0;
  if (thin) {
    found = tree_.within_thinned(q, r2, max_points, out);  // keep_evenly of the tree-order list
    // (squared distance, tree index) pairs order as the kd-tree's sorted keys
    if (sorted) KdTree3::sort_entries(out);
  } else if (sorted && !xs_.empty()) {
    scan_within(q, r2, out);
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
