// PCL's FPFH at keypoints (pcl::FPFHEstimationOMP, 33 bins), the reference
// for our own (fpfh.cpp; tests/test_recognition_local_fpfh.cpp compares
// them). Not used by the pipeline.
#include <pcl/features/fpfh_omp.h>

#include "recognition/local/internal.h"
#include "recognition/local/pcl_features.h"
#include "pcl_reference.h"

namespace pb::local {

std::vector<float> compute_fpfh_pcl(const PointSet& cloud, const std::vector<int>& keypoints,
                                double radius_mm, int threads) {
  pcl::FPFHEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> est;
  return describe_keypoints<pcl::FPFHSignature33>(
      est, cloud, keypoints, radius_mm, threads, kFpfhDim, [](const pcl::FPFHSignature33& x) { return x.histogram; }, false);
}

}  // namespace pb::local
