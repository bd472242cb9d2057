// Keypoints of the local pipeline: a second, coarser voxel grid (THESIS.md
// "Local pipeline" step 1). PCL-free.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "recognition/local/internal.h"

namespace pb::local {

std::vector<int> voxel_keypoints(const PointSet& cloud, double voxel_mm) {
  std::vector<int> out;
  if (cloud.empty() || !(voxel_mm > 0)) return out;
  const double inv = 1.0 / voxel_mm;
  // (voxel key, point index) for every finite point; keys pack three 21-bit
  // signed cell coordinates (+-1e6 cells: far beyond any sensor range).
  std::vector<std::pair<uint64_t, int>> keyed;
  keyed.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Vec3f& p = cloud.points[i];
    if (!p.allFinite()) continue;
    uint64_t key = 0;
    for (int a = 0; a < 3; ++a) {
      const int64_t c = static_cast<int64_t>(std::floor(p[a] * inv)) + (int64_t(1) << 20);
      key = (key << 21) | (static_cast<uint64_t>(std::clamp<int64_t>(c, 0, (int64_t(1) << 21) - 1)));
    }
    keyed.emplace_back(key, static_cast<int>(i));
  }
  std::sort(keyed.begin(), keyed.end());
  for (size_t b = 0; b < keyed.size();) {
    size_t e = b;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    while (e < keyed.size() && keyed[e].first == keyed[b].first) {
      c += cloud.points[keyed[e].second].cast<double>();
      ++e;
    }
    c /= static_cast<double>(e - b);
    int best = -1;
    double best_d = std::numeric_limits<double>::max();
    for (size_t j = b; j < e; ++j) {  // indices ascending within a voxel: ties -> lowest index
      const double d = (cloud.points[keyed[j].second].cast<double>() - c).squaredNorm();
      if (d < best_d) {
        best_d = d;
        best = keyed[j].second;
      }
    }
    out.push_back(best);
    b = e;
  }
  return out;
}

bool finite_row(const float* row, int dim) {
  for (int i = 0; i < dim; ++i)
    if (!std::isfinite(row[i])) return false;
  return true;
}

}  // namespace pb::local
