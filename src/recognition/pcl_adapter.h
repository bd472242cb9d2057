// PointSet / point vectors <-> PCL clouds: the one adapter every stage uses.
// Private to src/recognition (.cpp files only): it includes PCL, which stays
// out of every other header. Units are passed through (mm unless `scale`).
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <vector>

#include "core/types.h"
#include "recognition/cloud.h"

namespace pb::pcl_adapter {

using XyzCloud = pcl::PointCloud<pcl::PointXYZ>;
using NormalCloud = pcl::PointCloud<pcl::Normal>;
using PointNormalCloud = pcl::PointCloud<pcl::PointNormal>;

// Points (optionally scaled, e.g. 1e-3 for metres).
inline XyzCloud::Ptr xyz(const std::vector<Vec3f>& pts, float scale = 1.0f) {
  XyzCloud::Ptr c(new XyzCloud);
  c->resize(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) (*c)[i].getVector3fMap() = pts[i] * scale;
  return c;
}

// The points at `indices`.
template <typename Index>
XyzCloud::Ptr xyz(const std::vector<Vec3f>& pts, const std::vector<Index>& indices) {
  XyzCloud::Ptr c(new XyzCloud);
  c->resize(indices.size());
  for (size_t i = 0; i < indices.size(); ++i) (*c)[i].getVector3fMap() = pts[static_cast<size_t>(indices[i])];
  return c;
}

// Normals with curvature (0 where the set has none).
inline NormalCloud::Ptr normals(const std::vector<Vec3f>& n, const std::vector<float>& curvature = {}) {
  NormalCloud::Ptr c(new NormalCloud);
  c->resize(n.size());
  const bool has_c = curvature.size() == n.size();
  for (size_t i = 0; i < n.size(); ++i) {
    (*c)[i].getNormalVector3fMap() = n[i];
    (*c)[i].curvature = has_c ? curvature[i] : 0.0f;
  }
  return c;
}

// Points and normals in one cloud (curvature 0), points optionally scaled.
inline PointNormalCloud::Ptr point_normals(const std::vector<Vec3f>& pts, const std::vector<Vec3f>& n,
                                           float scale = 1.0f) {
  PointNormalCloud::Ptr c(new PointNormalCloud);
  c->resize(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    (*c)[i].getVector3fMap() = pts[i] * scale;
    (*c)[i].getNormalVector3fMap() = n[i];
    (*c)[i].curvature = 0;
  }
  return c;
}

// Back: the xyz of any PCL point type.
template <typename PointT>
std::vector<Vec3f> points(const pcl::PointCloud<PointT>& c) {
  std::vector<Vec3f> p(c.size());
  for (size_t i = 0; i < c.size(); ++i) p[i] = c[i].getVector3fMap();
  return p;
}

}  // namespace pb::pcl_adapter
