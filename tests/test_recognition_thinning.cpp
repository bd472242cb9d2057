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
#include "recognition/preprocess/preprocess.h"
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
  radius_normals(full, 22.0, 0);
  radius_normals(thin, 22.0, 16);
  ASSERT_EQ(full.size(), thin.size());
  size_t close = 0, differ = 0;
  for (size_t i = 0; i < full.size(); ++i) {
    close += full.normals[i].dot(thin.normals[i]) > std::cos(3 * M_PI / 180);
    differ += full.normals[i] != thin.normals[i];
  }
  EXPECT_GT(differ, full.size() / 2) << "the cap must bind here";
  EXPECT_GE(close, full.size() * 99 / 100);
  PointSet same = plane;
  radius_normals(same, 22.0, 100000);
  EXPECT_EQ(same.normals, full.normals);
}

// The coarse support (preprocess.normal_coarse_support): on a noisy sphere
// seen from the origin, where the true normal is known, normals from the
// centroids of a coarse grid are as close to it as those from the thinned
// points; a small isolated cluster, too sparse for the coarse grid, still
// gets its normals (from its own points).
double angle_deg(const Vec3f& a, const Vec3f& b) {
  return std::acos(std::clamp(static_cast<double>(a.normalized().dot(b.normalized())), -1.0, 1.0)) * 180 / M_PI;
}

TEST(ThinningNormals, ACoarseSupportIsAsCloseToTheTrueNormal) {
  const Vec3f centre(0, 0, 3000);
  const double R = 800;
  PointSet sphere;
  Rng rng(11);
  for (int i = -45; i <= 45; ++i)  // the near cap, about 20 mm apart, 2 mm of noise along the radius
    for (int j = -45; j <= 45; ++j) {
      const Vec3f d = Vec3f(0.025f * i, 0.025f * j, -1.f).normalized();
      sphere.points.push_back(centre + d * static_cast<float>(R + rng.normal(0, 2)));
    }
  PointSet cluster = sphere;  // and 10 points of a 30 mm patch 1 m in front of it
  for (int k = 0; k < 10; ++k)
    cluster.points.emplace_back(static_cast<float>(rng.uniform(-15, 15)), static_cast<float>(rng.uniform(-15, 15)),
                                2000.f);
  PointSet thin = cluster, coarse = cluster;
  radius_normals(thin, 180.0, 64);
  radius_normals(coarse, 180.0, 64, 40.0);
  ASSERT_EQ(thin.size(), cluster.size());
  ASSERT_EQ(coarse.size(), cluster.size()) << "every point keeps a normal, the isolated patch's included";
  size_t differ = 0;  // the coarse support must serve here, not the fallback to the points
  for (size_t i = 0; i < sphere.size(); ++i) differ += thin.normals[i] != coarse.normals[i];
  EXPECT_GT(differ, sphere.size() * 9 / 10);
  std::vector<double> e_thin, e_coarse;
  for (size_t i = 0; i < sphere.size(); ++i) {
    const int gi = static_cast<int>(i) / 91 - 45, gj = static_cast<int>(i) % 91 - 45;
    if (std::abs(gi) > 30 || std::abs(gj) > 30) continue;  // balls cut by the cap's border tilt either normal
    const Vec3f truth = sphere.points[i] - centre;  // outward: toward the viewer at the origin
    e_thin.push_back(angle_deg(thin.normals[i], truth));
    e_coarse.push_back(angle_deg(coarse.normals[i], truth));
  }
  auto pct = [](std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1))];
  };
  // The 180 mm ball on an 800 mm sphere tilts a PCA normal only slightly
  // (the cap is symmetric about the point); either support is within
  // a degree of the truth for nearly every point.
  EXPECT_LT(pct(e_thin, 0.95), 1.0);
  EXPECT_LT(pct(e_coarse, 0.95), 1.0);
  EXPECT_LT(pct(e_coarse, 0.5), 1.5 * pct(e_thin, 0.5) + 0.1);
  for (size_t i = sphere.size(); i < cluster.size(); ++i)
    EXPECT_LT(angle_deg(coarse.normals[i], Vec3f(0, 0, -1)), 1.0) << "the isolated patch faces the camera";
}

TEST(ThinningNormals, TheCoarseSupportServesOnlyWhereABallHoldsManyVoxels) {
  PreprocessSettings table;  // defaults: 10 mm voxels, 20 mm normals
  EXPECT_EQ(table.normal_support_leaf_mm(), 0.0);
  PreprocessSettings warehouse;  // as the LS5's warehouse runs resolve it
  warehouse.voxel_mm = 20;
  warehouse.normal_radius_mm = 181.6;
  EXPECT_NEAR(warehouse.normal_support_leaf_mm(), 181.6 * std::sqrt(M_PI / 64), 1e-9);
  warehouse.normal_coarse_support = false;
  EXPECT_EQ(warehouse.normal_support_leaf_mm(), 0.0);
  warehouse.normal_coarse_support = true;
  warehouse.normal_max_points = 0;  // no cap: every point, as PCL
  EXPECT_EQ(warehouse.normal_support_leaf_mm(), 0.0);
}

}  // namespace
}  // namespace pb
