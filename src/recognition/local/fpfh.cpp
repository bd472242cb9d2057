// FPFH descriptors at keypoints (pcl::FPFHEstimationOMP, 33 bins). Each
// output row is computed from its own neighbourhood only, so the result is
// the same for any thread count. The estimator is local to the call (no
// shared state between threads).
#include <pcl/features/fpfh_omp.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <limits>

#include "recognition/local/internal.h"

namespace pb::local {

std::vector<float> compute_fpfh(const PointSet& cloud, const std::vector<int>& keypoints,
                                double radius_mm, int threads) {
  std::vector<float> out(keypoints.size() * kFpfhDim, std::numeric_limits<float>::quiet_NaN());
  if (keypoints.empty() || !cloud.has_normals()) return out;

  pcl::PointCloud<pcl::PointXYZ>::Ptr surface(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  surface->resize(cloud.size());
  normals->resize(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    (*surface)[i].getVector3fMap() = cloud.points[i];
    (*normals)[i].getNormalVector3fMap() = cloud.normals[i];
    (*normals)[i].curvature = cloud.curvature.size() == cloud.size() ? cloud.curvature[i] : 0.f;
  }
  pcl::PointCloud<pcl::PointXYZ>::Ptr input(new pcl::PointCloud<pcl::PointXYZ>);
  input->resize(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) (*input)[i] = (*surface)[keypoints[i]];

  pcl::FPFHEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> est;
  est.setNumberOfThreads(threads < 0 ? 0u : static_cast<unsigned>(threads));
  est.setInputCloud(input);
  est.setSearchSurface(surface);
  est.setInputNormals(normals);
  est.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  est.setRadiusSearch(radius_mm);
  pcl::PointCloud<pcl::FPFHSignature33> desc;
  est.compute(desc);
  if (desc.size() != keypoints.size()) return out;
  for (size_t i = 0; i < desc.size(); ++i)
    for (int d = 0; d < kFpfhDim; ++d) out[i * kFpfhDim + d] = desc[i].histogram[d];
  return out;
}

}  // namespace pb::local
