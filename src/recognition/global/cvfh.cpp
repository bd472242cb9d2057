// CVFH signatures through pcl::CVFHEstimation.
#include <pcl/features/cvfh.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <cmath>

#include "recognition/global/internal.h"

namespace pb::global {

std::vector<Signature> cvfh_signatures(const PointSet& cloud, const GlobalSettings& s) {
  std::vector<Signature> out;
  if (!cloud.has_normals()) return out;
  const size_t n = cloud.points.size();
  const bool has_c = cloud.curvature.size() == n;
  pcl::PointCloud<pcl::PointXYZ>::Ptr pts(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr nrm(new pcl::PointCloud<pcl::Normal>);
  for (size_t i = 0; i < n; ++i) {
    if (!cloud.points[i].allFinite() || !cloud.normals[i].allFinite()) continue;
    pcl::PointXYZ p;
    p.getVector3fMap() = cloud.points[i];
    pcl::Normal q;
    q.getNormalVector3fMap() = cloud.normals[i];
    q.curvature = has_c && std::isfinite(cloud.curvature[i]) ? cloud.curvature[i] : 0.f;
    pts->push_back(p);
    nrm->push_back(q);
  }
  // VFH needs a few points to be meaningful (and PCL's estimators misbehave
  // on near-empty input).
  if (pts->size() < 10) return out;

  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  pcl::CVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308> cvfh;
  cvfh.setInputCloud(pts);
  cvfh.setInputNormals(nrm);
  cvfh.setSearchMethod(tree);
  cvfh.setViewPoint(0.f, 0.f, 0.f);
  cvfh.setEPSAngleThreshold(static_cast<float>(s.cvfh_eps_angle_deg * M_PI / 180.0));
  cvfh.setCurvatureThreshold(static_cast<float>(s.cvfh_curvature_threshold));
  cvfh.setClusterTolerance(static_cast<float>(s.cvfh_cluster_tolerance_mm));
  cvfh.setRadiusNormals(static_cast<float>(s.cvfh_normal_radius_mm));
  cvfh.setMinPoints(static_cast<size_t>(std::max(s.cvfh_min_region_points, 1)));
  cvfh.setNormalizeBins(s.cvfh_normalize_bins);
  pcl::PointCloud<pcl::VFHSignature308> sigs;
  cvfh.compute(sigs);

  std::vector<Eigen::Vector3f, Eigen::aligned_allocator<Eigen::Vector3f>> centroids, normals;
  cvfh.getCentroidClusters(centroids);
  cvfh.getCentroidNormalClusters(normals);
  const bool with_normals = normals.size() == sigs.size();
  for (size_t k = 0; k < sigs.size() && k < centroids.size(); ++k) {
    Signature sig;
    sig.hist.assign(sigs[k].histogram, sigs[k].histogram + 308);
    bool finite = true;
    for (float v : sig.hist) finite = finite && std::isfinite(v);
    if (!finite) continue;
    sig.centroid = centroids[k];
    if (with_normals && normals[k].allFinite() && normals[k].norm() > 0.5f) {
      sig.axis = -normals[k].normalized();
      sig.from_normal = true;
    } else {
      sig.axis = centroids[k].normalized();
    }
    out.push_back(std::move(sig));
  }
  return out;
}

}  // namespace pb::global
