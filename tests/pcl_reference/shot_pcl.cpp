// PCL's SHOT at keypoints (pcl::SHOTEstimationOMP, 352 bins; its local
// reference frame from the distance-weighted covariance), the reference for
// our own (shot.cpp; tests/test_recognition_local_shot.cpp compares them).
// Not used by the pipeline. Keypoints whose reference frame PCL finds
// invalid get NaN rows (PCL issue 5474).
#include <pcl/features/shot_omp.h>

#include "recognition/local/internal.h"
#include "recognition/local/pcl_features.h"
#include "pcl_reference.h"

namespace pb::local {

std::vector<float> compute_shot_pcl(const PointSet& cloud, const std::vector<int>& keypoints,
                                    double radius_mm, int threads) {
  pcl::SHOTEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::SHOT352> est;
  // An invalid frame leaves NaN (or, for some paths, an all-zero descriptor):
  // both are unusable.
  return describe_keypoints<pcl::SHOT352>(
      est, cloud, keypoints, radius_mm, threads, kShotDim, [](const pcl::SHOT352& x) { return x.descriptor; }, true);
}

}  // namespace pb::local
