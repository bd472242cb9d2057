// FPFH descriptors at keypoints (pcl::FPFHEstimationOMP, 33 bins). Each
// output row is computed from its own neighbourhood only, so the result is
// the same for any thread count. The estimator is local to the call (no
// shared state between threads).
#include <pcl/features/fpfh_omp.h>

#include "recognition/local/internal.h"
#include "recognition/local/pcl_features.h"

namespace pb::local {

std::vector<float> compute_fpfh(const PointSet& cloud, const std::vector<int>& keypoints,
                                double radius_mm, int threads) {
  pcl::FPFHEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> est;
  return describe_keypoints<pcl::FPFHSignature33>(
      est, cloud, keypoints, radius_mm, threads, kFpfhDim, [](const pcl::FPFHSignature33& x) { return x.histogram; }, false);
}

}  // namespace pb::local
