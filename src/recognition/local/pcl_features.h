// The one set-up of a PCL feature estimator at keypoints (FPFH, SHOT, BOARD
// frames), private to local/*.cpp (includes PCL): the keypoints are the
// input, the whole cloud with its normals the search surface, searched by a
// kd-tree within radius_mm. Returns false if PCL did not give one output per
// keypoint.
#pragma once

#include <pcl/search/kdtree.h>

#include <vector>

#include "recognition/cloud.h"
#include "recognition/pcl_adapter.h"

namespace pb::local {

template <typename Estimator, typename OutCloud>
bool estimate_at_keypoints(Estimator& est, const PointSet& cloud, const std::vector<int>& keypoints,
                           double radius_mm, OutCloud& out) {
  est.setInputCloud(pcl_adapter::xyz(cloud.points, keypoints));
  est.setSearchSurface(pcl_adapter::xyz(cloud.points));
  est.setInputNormals(pcl_adapter::normals(cloud.normals, cloud.curvature));
  est.setSearchMethod(pcl::search::KdTree<pcl::PointXYZ>::Ptr(new pcl::search::KdTree<pcl::PointXYZ>));
  est.setRadiusSearch(radius_mm);
  est.compute(out);
  return out.size() == keypoints.size();
}

}  // namespace pb::local
