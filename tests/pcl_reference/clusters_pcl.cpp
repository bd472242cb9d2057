// pcl::EuclideanClusterExtraction, the reference of the project's own
// Euclidean clusters (euclidean.cpp): tests and benchmarks only.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <algorithm>
#include <cmath>

#include "recognition/pcl_adapter.h"
#include "recognition/global/internal.h"
#include "pcl_reference.h"

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

}  // namespace pb::global
