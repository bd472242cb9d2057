// Our SHOT (local/shot.cpp) against PCL's SHOTEstimationOMP (tests/pcl_reference/shot_pcl.cpp) on
// the same keypoints, cloud and normals: a noisy, curved surface with
// jittered sample positions, plus a duplicated point, a NaN point and a
// keypoint with too few neighbours. Also: one and two threads give the same
// rows bit for bit, and a moved copy of the surface gives the same
// descriptors (rigid invariance).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "core/random.h"
#include "core/rotation.h"
#include "recognition/local/internal.h"
#include "test_recognition_local_util.h"
#include "pcl_reference.h"  // PCL's implementation, the reference

namespace pb {
namespace {

using localtest::every_nth;
using localtest::noisy_surface;

double row_distance(const std::vector<float>& a, const std::vector<float>& b, size_t r) {
  double d = 0;
  for (int j = 0; j < local::kShotDim; ++j) {
    const double e = a[r * local::kShotDim + j] - b[r * local::kShotDim + j];
    d += e * e;
  }
  return std::sqrt(d);
}

TEST(LocalShot, MatchesPclShot) {
  PointSet cloud = noisy_surface(3);
  cloud.points.push_back(cloud.points[100]);  // a duplicate: left out of the frame, skipped by the histogram
  cloud.normals.push_back(cloud.normals[100]);
  cloud.points.emplace_back(NAN, NAN, NAN);  // never a neighbour
  cloud.normals.emplace_back(0, 0, -1);
  cloud.points.emplace_back(0.f, 0.f, 2000.f);  // alone: too few neighbours, no frame
  cloud.normals.emplace_back(0, 0, -1);
  const int nan_kp = static_cast<int>(cloud.size()) - 2, lone_kp = static_cast<int>(cloud.size()) - 1;
  std::vector<int> kp = every_nth(cloud.size() - 3, 7);
  kp.push_back(100);
  kp.push_back(lone_kp);
  const double radius = 20;
  const std::vector<float> pcl = local::compute_shot_pcl(cloud, kp, radius, 1);
  // PCL asserts on a NaN keypoint (its frame's radius search): ours alone.
  kp.push_back(nan_kp);
  std::vector<float> ours = local::compute_shot(cloud, kp, radius, 1);
  const std::vector<float> nan_row(ours.end() - local::kShotDim, ours.end());
  for (float v : nan_row) EXPECT_TRUE(std::isnan(v)) << "the NaN keypoint";
  ours.resize(pcl.size());
  kp.pop_back();
  ASSERT_EQ(ours.size(), pcl.size());
  const size_t rows = kp.size();
  size_t close = 0;
  double worst = 0;
  for (size_t r = 0; r + 1 < rows; ++r) {
    double norm = 0;
    for (int j = 0; j < local::kShotDim; ++j) {
      ASSERT_TRUE(std::isfinite(ours[r * local::kShotDim + j])) << "row " << r;
      ASSERT_TRUE(std::isfinite(pcl[r * local::kShotDim + j])) << "row " << r;
      norm += double(ours[r * local::kShotDim + j]) * ours[r * local::kShotDim + j];
    }
    EXPECT_NEAR(norm, 1.0, 1e-4) << "unit L2 norm";
    const double d = row_distance(ours, pcl, r);
    worst = std::max(worst, d);
    close += d < 1e-4;
  }
  EXPECT_GE(close, (rows - 1) * 95 / 100) << "rows within 1e-4 (L2) of PCL's";
  EXPECT_LT(worst, 0.05) << "no row far from PCL's (a frame axis flipped would be ~1)";
  for (int j = 0; j < local::kShotDim; ++j) {  // the lone keypoint
    EXPECT_TRUE(std::isnan(ours[(rows - 1) * local::kShotDim + j]));
    EXPECT_TRUE(std::isnan(pcl[(rows - 1) * local::kShotDim + j]));
  }
  std::printf("rows within 1e-4 of PCL's: %zu of %zu, largest L2 difference %.3g\n", close, rows - 1, worst);
}

TEST(LocalShot, ThreadsAndRigidMotionDoNotChangeIt) {
  const PointSet cloud = noisy_surface(5);
  const std::vector<int> kp = every_nth(cloud.size(), 5);
  const std::vector<float> one = local::compute_shot(cloud, kp, 18, 1);
  EXPECT_EQ(one, local::compute_shot(cloud, kp, 18, 2));
  PointSet moved = cloud;
  const Mat3 R = axis_angle(Vec3(1, -2, 0.5).normalized(), 0.7);
  for (size_t i = 0; i < cloud.size(); ++i) {
    moved.points[i] = (R * cloud.points[i].cast<double>() + Vec3(30, -20, 50)).cast<float>();
    moved.normals[i] = (R * cloud.normals[i].cast<double>()).cast<float>();
  }
  const std::vector<float> two = local::compute_shot(moved, kp, 18, 1);
  size_t close = 0;
  for (size_t r = 0; r < kp.size(); ++r) close += row_distance(one, two, r) < 1e-3;
  EXPECT_GE(close, kp.size() * 95 / 100);
  for (float v : local::compute_shot(cloud, kp, 0, 1)) EXPECT_TRUE(std::isnan(v));
}

}  // namespace
}  // namespace pb
