// Scene segmentation (Euclidean clusters) and CVFH's stable regions, for the
// global pipeline. PCL inside.
#include <pcl/features/normal_3d.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>
#include <cmath>

#include "recognition/pcl_adapter.h"
#include "recognition/global/internal.h"

namespace pb::global {

std::vector<std::vector<int>> euclidean_clusters_pcl(const std::vector<Vec3f>& points, double tolerance_mm,
                                                     int min_points, int max_points) {
  std::vector<std::vector<int>> out;
  if (points.empty() || static_cast<int>(points.size()) < std::max(min_points, 1)) return out;
  const auto cloud = pcl_adapter::xyz(points);
  pcl::search::KdTree<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  tree->setInputCloud(cloud);
  pcl::EuclideanClusterExtraction<pcl::PointXYZ> ec;
  ec.setClusterTolerance(static_cast<float>(tolerance_mm));
  ec.setMinClusterSize(std::max(min_points, 1));
  ec.setMaxClusterSize(std::max(max_points, 1));
  ec.setSearchMethod(tree);
  ec.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  ec.extract(clusters);
  for (const auto& c : clusters) {
    std::vector<int> idx(c.indices.begin(), c.indices.end());
    std::sort(idx.begin(), idx.end());
    out.push_back(std::move(idx));
  }
  // Largest first; ties by the first index, so the order never depends on
  // the sort implementation.
  std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
    if (a.size() != b.size()) return a.size() > b.size();
    return a.front() < b.front();
  });
  return out;
}

std::vector<Region> stable_regions(const PointSet& cloud, const GlobalSettings& s) {
  std::vector<Region> regions;
  const size_t n = cloud.points.size();
  const bool has_c = cloud.curvature.size() == n;
  const size_t min_pts = static_cast<size_t>(std::max(s.cvfh_min_region_points, 1));

  // Step 0 (as CVFH): drop the points of high curvature.
  pcl::PointCloud<pcl::PointNormal>::Ptr filtered(new pcl::PointCloud<pcl::PointNormal>);
  for (size_t i = 0; i < n; ++i) {
    if (!cloud.points[i].allFinite()) continue;
    if (has_c && !(cloud.curvature[i] <= s.cvfh_curvature_threshold)) continue;
    pcl::PointNormal p;
    p.getVector3fMap() = cloud.points[i];
    p.getNormalVector3fMap() = Vec3f::Zero();
    p.curvature = 0;
    filtered->push_back(p);
  }
  if (filtered->size() < min_pts) return regions;

  // Normals recomputed on the remaining points, toward the camera (origin).
  pcl::search::KdTree<pcl::PointNormal>::Ptr tree(new pcl::search::KdTree<pcl::PointNormal>(false));
  tree->setInputCloud(filtered);
  {
    pcl::NormalEstimation<pcl::PointNormal, pcl::PointNormal> ne;
    ne.setRadiusSearch(s.cvfh_normal_radius_mm);
    ne.setSearchMethod(tree);
    ne.setInputCloud(filtered);
    ne.setViewPoint(0.f, 0.f, 0.f);
    ne.compute(*filtered);
  }
  tree->setInputCloud(filtered);  // same points; the normals changed

  // Smooth region growing (CVFH's extractEuclideanClustersSmooth): a
  // neighbour within the tolerance joins when its normal is within the
  // angle of the normal of the point that reached it.
  const double eps = s.cvfh_eps_angle_deg * M_PI / 180.0;
  const float tol = static_cast<float>(s.cvfh_cluster_tolerance_mm);
  std::vector<char> processed(filtered->size(), 0);
  pcl::Indices nn;
  std::vector<float> nd;
  for (size_t i = 0; i < filtered->size(); ++i) {
    if (processed[i]) continue;
    processed[i] = 1;
    std::vector<int> queue{static_cast<int>(i)};
    for (size_t q = 0; q < queue.size(); ++q) {
      const int seed = queue[q];
      const Vec3f ns = (*filtered)[seed].getNormalVector3fMap();
      if (!ns.allFinite()) continue;
      if (tree->radiusSearch(seed, tol, nn, nd) <= 0) continue;
      // As PCL's CVFH, the first neighbour returned is skipped (it assumes
      // it is the seed itself, which an unsorted search does not promise);
      // kept so the regions are exactly CVFH's.
      for (size_t jj = 1; jj < nn.size(); ++jj) {
        const auto j = nn[jj];
        if (processed[j]) continue;
        const Vec3f nj = (*filtered)[j].getNormalVector3fMap();
        const double dot = ns.dot(nj);
        if (std::acos(std::clamp(dot, -1.0, 1.0)) < eps && nj.allFinite()) {
          processed[j] = 1;
          queue.push_back(j);
        }
      }
    }
    if (queue.size() < min_pts) continue;
    std::sort(queue.begin(), queue.end());
    Region r;
    Eigen::Vector3d c = Eigen::Vector3d::Zero(), nsum = Eigen::Vector3d::Zero();
    for (int k : queue) {
      const auto& p = (*filtered)[k];
      r.points.push_back(p.getVector3fMap());
      r.normals.push_back(p.getNormalVector3fMap());
      c += p.getVector3fMap().cast<double>();
      nsum += p.getNormalVector3fMap().cast<double>();
    }
    r.centroid = (c / static_cast<double>(queue.size())).cast<float>();
    if (nsum.norm() > 0) r.mean_normal = nsum.normalized().cast<float>();
    regions.push_back(std::move(r));
  }
  return regions;
}

}  // namespace pb::global
