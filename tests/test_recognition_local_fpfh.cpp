// Our FPFH (local/fpfh.cpp) against PCL's FPFHEstimationOMP (tests/pcl_reference/fpfh_pcl.cpp)
// on the same keypoints, cloud and normals: a noisy, curved surface with
// jittered sample positions (so no pair sits exactly on a radius or bin
// boundary by construction), plus a NaN point and a duplicated point. Also:
// one and two threads give the same rows bit for bit, and the descriptor of
// a moved copy of the surface equals the original's (rigid invariance).
#include <gtest/gtest.h>

#include <cmath>

#include "core/random.h"
#include "core/rotation.h"
#include "recognition/local/internal.h"
#include "test_recognition_local_util.h"
#include "pcl_reference.h"  // PCL's implementation, the reference

namespace pb {
namespace {

using localtest::every_nth;
using localtest::noisy_surface;

TEST(LocalFpfh, MatchesPclFpfh) {
  PointSet cloud = noisy_surface(3);
  cloud.points.push_back(cloud.points[100]);  // a duplicate: distance 0, skipped by both
  cloud.normals.push_back(cloud.normals[100]);
  cloud.points.emplace_back(NAN, NAN, NAN);  // never a neighbour
  cloud.normals.emplace_back(0, 0, -1);
  std::vector<int> kp = every_nth(cloud.size() - 1, 7);
  kp.push_back(static_cast<int>(cloud.size() - 1));  // the NaN keypoint: a NaN row in both
  const double radius = 18;
  const std::vector<float> ours = local::compute_fpfh(cloud, kp, radius, 1);
  const std::vector<float> pcl = local::compute_fpfh_pcl(cloud, kp, radius, 1);
  ASSERT_EQ(ours.size(), pcl.size());
  double max_diff = 0;
  size_t rows_equal = 0;
  const size_t rows = kp.size();
  for (size_t r = 0; r + 1 < rows; ++r) {
    double row_diff = 0, sum = 0;
    for (int j = 0; j < local::kFpfhDim; ++j) {
      const float a = ours[r * local::kFpfhDim + j], b = pcl[r * local::kFpfhDim + j];
      ASSERT_TRUE(std::isfinite(a)) << "row " << r;
      row_diff = std::max(row_diff, static_cast<double>(std::abs(a - b)));
      sum += a;
    }
    EXPECT_NEAR(sum, 300.0, 1e-2) << "each of the three histograms sums to 100";
    max_diff = std::max(max_diff, row_diff);
    if (row_diff < 1e-3) ++rows_equal;
  }
  EXPECT_LT(max_diff, 0.05) << "bins of 0..100";
  EXPECT_GE(rows_equal, (rows - 1) * 95 / 100);
  for (int j = 0; j < local::kFpfhDim; ++j) {
    EXPECT_TRUE(std::isnan(ours[(rows - 1) * local::kFpfhDim + j]));
    EXPECT_TRUE(std::isnan(pcl[(rows - 1) * local::kFpfhDim + j]));
  }
}

TEST(LocalFpfh, ThreadsAndRigidMotionDoNotChangeIt) {
  const PointSet cloud = noisy_surface(5);
  const std::vector<int> kp = every_nth(cloud.size(), 5);
  const std::vector<float> one = local::compute_fpfh(cloud, kp, 16, 1);
  EXPECT_EQ(one, local::compute_fpfh(cloud, kp, 16, 2));

  PointSet moved = cloud;
  const Mat3 R = axis_angle(Vec3(1, -2, 0.5).normalized(), 0.7);
  for (size_t i = 0; i < cloud.size(); ++i) {
    moved.points[i] = (R * cloud.points[i].cast<double>() + Vec3(30, -20, 50)).cast<float>();
    moved.normals[i] = (R * cloud.normals[i].cast<double>()).cast<float>();
  }
  const std::vector<float> two = local::compute_fpfh(moved, kp, 16, 1);
  double max_diff = 0;
  for (size_t i = 0; i < one.size(); ++i) max_diff = std::max(max_diff, static_cast<double>(std::abs(one[i] - two[i])));
  EXPECT_LT(max_diff, 0.05);
  // A wrong radius is no descriptor at all (not a crash).
  for (float v : local::compute_fpfh(cloud, kp, 0, 1)) EXPECT_TRUE(std::isnan(v));
}

}  // namespace
}  // namespace pb
