// SHOT descriptors at keypoints (pcl::SHOTEstimationOMP, 352 bins; its local
// reference frame from the distance-weighted covariance). Keypoints whose
// reference frame PCL finds invalid get NaN rows (PCL issue 5474): the caller
// drops them. Each row depends on its own neighbourhood only, so the result
// is the same for any thread count.
#include <pcl/features/shot_omp.h>

#include <limits>

#include "recognition/local/internal.h"
#include "recognition/local/pcl_features.h"

namespace pb::local {

std::vector<float> compute_shot(const PointSet& cloud, const std::vector<int>& keypoints,
                                double radius_mm, int threads) {
  std::vector<float> out(keypoints.size() * kShotDim, std::numeric_limits<float>::quiet_NaN());
  if (keypoints.empty() || !cloud.has_normals()) return out;

  pcl::SHOTEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::SHOT352> est;
  est.setNumberOfThreads(threads < 0 ? 0u : static_cast<unsigned>(threads));
  pcl::PointCloud<pcl::SHOT352> desc;
  if (!estimate_at_keypoints(est, cloud, keypoints, radius_mm, desc)) return out;
  for (size_t i = 0; i < desc.size(); ++i) {
    // An invalid frame leaves NaN (or, for some paths, an all-zero
    // descriptor): both are unusable.
    bool any = false;
    for (int d = 0; d < kShotDim; ++d) any = any || desc[i].descriptor[d] != 0.f;
    if (!any) continue;
    for (int d = 0; d < kShotDim; ++d) out[i * kShotDim + d] = desc[i].descriptor[d];
  }
  return out;
}

}  // namespace pb::local
