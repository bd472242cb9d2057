// Our FPFH (local/fpfh.cpp) against PCL's FPFHEstimationOMP (fpfh_pcl.cpp)
// on the same keypoints, cloud and normals: a noisy, curved surface with
// jittered sample positions (so no pair sits exactly on a radius or bin
// boundary by construction), plus a NaN point and a duplicated point. Also:
// one and two threads give the same rows bit for bit, and the descriptor of
// a moved copy of the surface equals the original's (rigid invariance).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/random.h"
#include "core/rotation.h"
#include "recognition/local/internal.h"
#include "test_recognition_local_util.h"

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

// f1_bin against binning atan2f's value (PCL's binning): random directions of
// every scale, the directions of the bin edges and the floats around them,
// the axes, signed zeros, the +-pi cut, and non-finite arguments.
TEST(LocalFpfh, F1BinIsTheBinOfAtan2) {
  const double inv_2pi = static_cast<double>(1.0f / (2.0f * static_cast<float>(M_PI)));
  const auto want = [&](float y, float x) {
    const double v = 11 * ((std::atan2(y, x) + M_PI) * inv_2pi);
    return v >= 0 ? std::min(static_cast<int>(std::floor(v)), 10) : 0;
  };
  size_t checked = 0, wrong = 0;
  const auto check = [&](float y, float x) {
    ++checked;
    if (local::f1_bin(y, x) != want(y, x) && ++wrong <= 5)
      ADD_FAILURE() << "y " << y << " x " << x << ": " << local::f1_bin(y, x) << " vs " << want(y, x);
  };
  Rng rng(3);
  for (int i = 0; i < 2000000; ++i) {
    const double s = std::pow(10.0, rng.uniform(-30, 30));
    check(static_cast<float>(rng.normal() * s), static_cast<float>(rng.normal() * s));
  }
  // The edges: directions at each bin's lower angle, and the floats around
  // their coordinates.
  for (int k = 0; k <= 11; ++k) {
    const double a = -M_PI + 2 * M_PI * k / 11.0;
    for (double d : {-1e-6, -1e-7, 0.0, 1e-7, 1e-6}) {
      const float y0 = static_cast<float>(std::sin(a + d)), x0 = static_cast<float>(std::cos(a + d));
      float y = y0;
      for (int j = 0; j < 8; ++j) y = std::nextafter(y, -2.0f);
      for (int j = 0; j < 17; ++j, y = std::nextafter(y, 2.0f)) {
        float x = x0;
        for (int m = 0; m < 8; ++m) x = std::nextafter(x, -2.0f);
        for (int m = 0; m < 17; ++m, x = std::nextafter(x, 2.0f)) check(y, x);
      }
    }
  }
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (float y : {0.f, -0.f, 1.f, -1.f, 1e-30f, -1e-30f, inf, -inf, nan})
    for (float x : {0.f, -0.f, 1.f, -1.f, 1e-30f, -1e-30f, inf, -inf, nan}) check(y, x);
  EXPECT_EQ(wrong, 0u) << "of " << checked;
  EXPECT_GT(checked, 2000000u);
}

}  // namespace
}  // namespace pb
