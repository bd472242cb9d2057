// FPFH descriptors at keypoints (pcl::FPFHEstimationOMP, 33 bins). Each
// output row is computed from its own neighbourhood only, so the result is
// the same for any thread count. The estimator is local to the call (no
// shared state between threads).
#include <pcl/features/fpfh_omp.h>

#include <limits>

#include "recognition/local/internal.h"
#include "recognition/local/pcl_features.h"

namespace pb::local {

std::vector<float> compute_fpfh(const PointSet& cloud, const std::vector<int>& keypoints,
                                double radius_mm, int threads) {
  std::vector<float> out(keypoints.size() * kFpfhDim, std::numeric_limits<float>::quiet_NaN());
  if (keypoints.empty() || !cloud.has_normals()) return out;

  pcl::FPFHEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> est;
  est.setNumberOfThreads(threads < 0 ? 0u : static_cast<unsigned>(threads));
  pcl::PointCloud<pcl::FPFHSignature33> desc;
  if (!estimate_at_keypoints(est, cloud, keypoints, radius_mm, desc)) return out;
  for (size_t i = 0; i < desc.size(); ++i)
    for (int d = 0; d < kFpfhDim; ++d) out[i * kFpfhDim + d] = desc[i].histogram[d];
  return out;
}

}  // namespace pb::local
