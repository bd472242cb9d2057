// The one set-up of a PCL feature estimator at keypoints (FPFH, SHOT, BOARD
// frames), private to local/*.cpp (includes PCL): the keypoints are the
// input, the whole cloud with its normals the search surface, searched by a
// kd-tree within radius_mm. Returns false if PCL did not give one output per
// keypoint.
#pragma once

#ifdef _OPENMP
#include <omp.h>
#endif

#include <pcl/search/kdtree.h>

#include <limits>
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

// Descriptors of an OpenMP estimator (FPFH, SHOT) at keypoints, row-major
// keypoints.size() x dim; NaN rows where PCL gave none, and, if
// zero_is_invalid, where it gave an all-zero descriptor. `values` maps a
// signature to its float array.
template <typename Signature, typename Estimator, typename Values>
std::vector<float> describe_keypoints(Estimator& est, const PointSet& cloud, const std::vector<int>& keypoints,
                                      double radius_mm, int threads, int dim, Values values, bool zero_is_invalid) {
  std::vector<float> out(keypoints.size() * dim, std::numeric_limits<float>::quiet_NaN());
  if (keypoints.empty() || !cloud.has_normals()) return out;
  // 0 = OpenMP's thread count (OMP_NUM_THREADS; PCL's own 0 would take
  // every core and oversubscribe `run --jobs N`).
#ifdef _OPENMP
  if (threads <= 0) threads = omp_get_max_threads();
#else
  threads = 1;
#endif
  est.setNumberOfThreads(static_cast<unsigned>(threads));
  pcl::PointCloud<Signature> desc;
  if (!estimate_at_keypoints(est, cloud, keypoints, radius_mm, desc)) return out;
  for (size_t i = 0; i < desc.size(); ++i) {
    const float* v = values(desc[i]);
    bool any = !zero_is_invalid;
    for (int d = 0; d < dim && !any; ++d) any = v[d] != 0.f;
    if (!any) continue;
    for (int d = 0; d < dim; ++d) out[i * dim + d] = v[d];
  }
  return out;
}

}  // namespace pb::local
