// What CVFH and OUR-CVFH share (private to global/*.cpp, includes PCL): the
// input cloud and the estimator set-up. OUR-CVFH runs in metres (PCL
// hard-codes a 1 cm sigma), CVFH in millimetres: `scale` maps mm to the
// estimator's unit.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <cmath>

#include "recognition/cloud.h"
#include "recognition/global/global.h"

namespace pb::global {

struct PclInput {
  pcl::PointCloud<pcl::PointXYZ>::Ptr points{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::PointCloud<pcl::Normal>::Ptr normals{new pcl::PointCloud<pcl::Normal>};
};

// The points with finite coordinates and normals (and, if unit_normals_only,
// normals of length 1 +- 0.01), scaled; curvature 0 where absent or not finite.
inline PclInput pcl_input(const PointSet& cloud, float scale, bool unit_normals_only) {
  PclInput in;
  const size_t n = cloud.points.size();
  const bool has_c = cloud.curvature.size() == n;
  for (size_t i = 0; i < n; ++i) {
    const Vec3f& nv = cloud.normals[i];
    if (!cloud.points[i].allFinite() || !nv.allFinite()) continue;
    if (unit_normals_only && std::abs(nv.norm() - 1.f) > 0.01f) continue;
    pcl::PointXYZ p;
    p.getVector3fMap() = cloud.points[i] * scale;
    pcl::Normal q;
    q.getNormalVector3fMap() = nv;
    q.curvature = has_c && std::isfinite(cloud.curvature[i]) ? cloud.curvature[i] : 0.f;
    in.points->push_back(p);
    in.normals->push_back(q);
  }
  return in;
}

// The settings both estimators read (pcl::CVFHEstimation and
// pcl::OURCVFHEstimation have the same setters).
template <typename Estimator>
void configure_cvfh_family(Estimator& est, const PclInput& in, const GlobalSettings& s, float scale) {
  est.setInputCloud(in.points);
  est.setInputNormals(in.normals);
  est.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  est.setViewPoint(0.f, 0.f, 0.f);
  est.setEPSAngleThreshold(static_cast<float>(s.cvfh_eps_angle_deg * M_PI / 180.0));
  est.setCurvatureThreshold(static_cast<float>(s.cvfh_curvature_threshold));
  est.setClusterTolerance(static_cast<float>(s.cvfh_cluster_tolerance_mm) * scale);
  est.setRadiusNormals(static_cast<float>(s.cvfh_normal_radius_mm) * scale);
  est.setMinPoints(static_cast<size_t>(std::max(s.cvfh_min_region_points, 1)));
  est.setNormalizeBins(s.cvfh_normalize_bins);
}

}  // namespace pb::global
