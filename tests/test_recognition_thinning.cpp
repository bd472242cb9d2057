// Thinning of large neighbourhoods (keep_evenly, kdtree.h): the cap on the
// points a normal (preprocess.normal_max_points) and an FPFH / SHOT
// histogram (local.max_support_points) are computed from. A cap above every
// neighbourhood changes nothing, bit for bit; a cap that binds keeps each
// descriptor much closer to its full version than to any other keypoint's,
// and normals within a few degrees; thread counts do not change the result.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "recognition/kdtree.h"
#include "recognition/local/internal.h"
#include "recognition/preprocess/internal.h"
#include "test_recognition_local_util.h"

namespace pb {
namespace {

using localtest::every_nth;
using localtest::noisy_surface;

TEST(KeepEvenly, KeepsEvenlySpacedEntriesInTheirOrder) {
  std::vector<int> v(1000);
  std::iota(v.begin(), v.end(), 0);
  keep_evenly(v, 100);
  ASSERT_EQ(v.size(), 100u);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(v[static_cast<size_t>(i)], 10 * i);
  std::vector<int> w(7);
  std::iota(w.begin(), w.end(), 0);
  keep_evenly(w, 3);  // floor(i * 7 / 3): 0, 2, 4
  EXPECT_EQ(w, (std::vector<int>{0, 2, 4}));
  std::vector<int> small{5, 3, 9};
  keep_evenly(small, 3);
  EXPECT_EQ(small, (std::vector<int>{5, 3, 9}));
  keep_evenly(small, 0);
  EXPECT_EQ(small, (std::vector<int>{5, 3, 9}));
}

double l1(const float* a, const float* b, int dim) {
  double d = 0;
  for (int j = 0; j < dim; ++j) d += std::abs(static_cast<double>(a[j]) - b[j]);
  return d;
}

using Describe = std::vector<float> (*)(const PointSet&, const std::vector<int>&, double, int, int);

struct Case {
  const char* name;
  Describe fn;
  int dim;
};

class Thinning : public ::testing::TestWithParam<Case> {};

// On the 4 mm surface a 30 mm radius holds about 175 points.
TEST_P(Thinning, ACapAboveEveryNeighbourhoodChangesNothing) {
  const PointSet cloud = noisy_surface(3);
  const std::vector<int> kp = every_nth(cloud.size(), 9);
  EXPECT_EQ(GetParam().fn(cloud, kp, 30, 1, 0), GetParam().fn(cloud, kp, 30, 1, 100000));
}

TEST_P(Thinning, ABindingCapKeepsEachRowNearItsFullRowAndIsThreadFree) {
  const PointSet cloud = noisy_surface(4);
  const std::vector<int> kp = every_nth(cloud.size(), 37);
  const int dim = GetParam().dim;
  const std::vector<float> full = GetParam().fn(cloud, kp, 30, 1, 0);
  const std::vector<float> thin = GetParam().fn(cloud, kp, 30, 1, 64);
  EXPECT_EQ(thin, GetParam().fn(cloud, kp, 30, 2, 64));
  ASSERT_NE(full, thin) << "the cap must bind here";
  int rows = 0, nearest_is_own = 0;
  std::vector<double> own, other;
  for (size_t i = 0; i < kp.size(); ++i) {
    const float* t = &thin[i * dim];
    if (!std::isfinite(t[0]) || !std::isfinite(full[i * dim])) continue;
    ++rows;
    own.push_back(l1(t, &full[i * dim], dim));
    size_t best = i;
    double best_d = own.back();
    for (size_t j = 0; j < kp.size(); ++j) {
      if (j == i || !std::isfinite(full[j * dim])) continue;
      const double d = l1(t, &full[j * dim], dim);
      other.push_back(d);
      if (d < best_d) best_d = d, best = j;
    }
    nearest_is_own += best == i;
  }
  ASSERT_GE(rows, 20);
  // The thinned row finds its own keypoint's full row first in nearly every
  // case, and lies far closer to it than keypoints typically lie to each other.
  EXPECT_GE(nearest_is_own, rows * 9 / 10) << GetParam().name;
  std::sort(own.begin(), own.end());
  std::sort(other.begin(), other.end());
  EXPECT_LT(own[own.size() / 2], 0.25 * other[other.size() / 2]) << GetParam().name;
}

std::vector<float> fpfh(const PointSet& c, const std::vector<int>& k, double r, int t, int m) {
  return local::compute_fpfh(c, k, r, t, m);
}
std::vector<float> shot(const PointSet& c, const std::vector<int>& k, double r, int t, int m) {
  return local::compute_shot(c, k, r, t, m);
}
INSTANTIATE_TEST_SUITE_P(Descriptors, Thinning,
                         ::testing::Values(Case{"fpfh", fpfh, local::kFpfhDim}, Case{"shot", shot, local::kShotDim}),
                         [](const auto& info) { return std::string(info.param.name); });

// Normals: 16 of the ~100 points within 22 mm of a noisy plane give normals
// within 3 degrees of the full neighbourhood's for nearly every point.
TEST(ThinningNormals, ACappedNeighbourhoodGivesNearlyTheSameNormal) {
  PointSet plane;
  Rng rng(7);
  for (int x = -40; x <= 40; ++x)
    for (int y = -40; y <= 40; ++y)
      plane.points.emplace_back(4.f * x + static_cast<float>(rng.uniform(-1, 1)),
                                4.f * y + static_cast<float>(rng.uniform(-1, 1)),
                                800.f + 0.3f * x + static_cast<float>(rng.normal(0, 0.5)));
  PointSet full = plane, thin = plane;
  detail::estimate_normals(full, 22.0, 0);
  detail::estimate_normals(thin, 22.0, 16);
  ASSERT_EQ(full.size(), thin.size());
  size_t close = 0, differ = 0;
  for (size_t i = 0; i < full.size(); ++i) {
    close += full.normals[i].dot(thin.normals[i]) > std::cos(3 * M_PI / 180);
    differ += full.normals[i] != thin.normals[i];
  }
  EXPECT_GT(differ, full.size() / 2) << "the cap must bind here";
  EXPECT_GE(close, full.size() * 99 / 100);
  PointSet same = plane;
  detail::estimate_normals(same, 22.0, 100000);
  EXPECT_EQ(same.normals, full.normals);
}

}  // namespace
}  // namespace pb
