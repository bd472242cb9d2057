// PointSet helpers (cloud.h).
#include "recognition/cloud.h"

namespace pb {

PointSet subset(const PointSet& cloud, const std::vector<int>& indices) {
  PointSet out;
  out.source_width = cloud.source_width;
  out.source_height = cloud.source_height;
  const size_t n = cloud.points.size();
  const bool has_n = cloud.normals.size() == n, has_c = cloud.curvature.size() == n,
             has_p = cloud.pixel.size() == n;
  out.points.reserve(indices.size());
  for (int i : indices) {
    out.points.push_back(cloud.points[i]);
    if (has_n) out.normals.push_back(cloud.normals[i]);
    if (has_c) out.curvature.push_back(cloud.curvature[i]);
    if (has_p) out.pixel.push_back(cloud.pixel[i]);
  }
  return out;
}

}  // namespace pb
