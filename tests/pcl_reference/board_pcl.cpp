// PCL's BOARD local reference frames (pcl::BOARDLocalReferenceFrameEstimation,
// holes filled, as PCL's correspondence grouping tutorial sets it up), the
// reference for our own (board.cpp; tests/test_recognition_local_board.cpp
// compares them). Not used by the pipeline. Its hole search starts from an
// axis drawn with std::rand(): the caller seeds it (std::srand) to repeat a
// result.
#include <pcl/features/board.h>

#include <limits>

#include "recognition/local/internal.h"
#include "recognition/local/pcl_features.h"
#include "pcl_reference.h"

namespace pb::local {

std::vector<float> compute_board_lrf_pcl(const PointSet& cloud, const std::vector<int>& keypoints,
                                         double radius_mm) {
  std::vector<float> out(keypoints.size() * kLrfDim, std::numeric_limits<float>::quiet_NaN());
  if (keypoints.empty() || !cloud.has_normals()) return out;

  pcl::BOARDLocalReferenceFrameEstimation<pcl::PointXYZ, pcl::Normal, pcl::ReferenceFrame> est;
  est.setFindHoles(true);
  pcl::PointCloud<pcl::ReferenceFrame> rf;
  if (!estimate_at_keypoints(est, cloud, keypoints, radius_mm, rf)) return out;
  for (size_t i = 0; i < rf.size(); ++i) {
    float row[kLrfDim];
    for (int d = 0; d < 3; ++d) {
      row[d] = rf[i].x_axis[d];
      row[3 + d] = rf[i].y_axis[d];
      row[6 + d] = rf[i].z_axis[d];
    }
    if (usable_frame(row)) std::copy(row, row + kLrfDim, out.begin() + static_cast<long>(i) * kLrfDim);
  }
  return out;
}

}  // namespace pb::local
