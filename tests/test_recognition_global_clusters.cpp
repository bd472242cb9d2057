// Our Euclidean clusters (global/euclidean.cpp, a grid of cells) against
// pcl::EuclideanClusterExtraction (tests/pcl_reference/clusters_pcl.cpp, the reference) on clouds
// whose components are close to the tolerance apart: the same clusters, in
// the same order, for tolerances from under a point spacing to many spacings,
// with the size limits applied as PCL applies them. The neighbour lookups go
// through their three structures: on the blobs, at 6, 11 and 15 mm the
// cells' box spans more than 2^20 cells (the cells by column), from 24 mm on
// fewer (the array); with a copy of the blobs 20 m away, from 6 to 47 mm
// the box's x-y extent spans more than 2^18 columns and 16 per cell (the
// hashed table), at 130 mm fewer (the columns).
#include <gtest/gtest.h>

#include <cmath>

#include "core/random.h"
#include "recognition/global/internal.h"
#include "pcl_reference.h"  // PCL's implementation, the reference

namespace pb {
namespace {

// Blobs of jittered points on a 10 mm lattice, some joined by thin bridges,
// some separated by gaps near typical tolerances, plus scattered singletons.
std::vector<Vec3f> blobs(uint64_t seed) {
  Rng rng(seed);
  std::vector<Vec3f> pts;
  for (int b = 0; b < 12; ++b) {
    const Vec3 c(rng.uniform(-400, 400), rng.uniform(-300, 300), rng.uniform(600, 1400));
    const int nx = 3 + static_cast<int>(rng.uniform(0, 12)), ny = 3 + static_cast<int>(rng.uniform(0, 12));
    for (int i = 0; i < nx; ++i)
      for (int j = 0; j < ny; ++j)
        pts.push_back((c + Vec3(10.0 * i + rng.uniform(-3, 3), 10.0 * j + rng.uniform(-3, 3), rng.uniform(-3, 3)))
                          .cast<float>());
    if (b % 3 == 0)  // a bridge toward the next blob's corner
      for (int k = 1; k < 20; ++k) pts.push_back((c + Vec3(-k * 9.0, -k * 7.0, k * 2.0)).cast<float>());
  }
  for (int k = 0; k < 40; ++k)
    pts.emplace_back(static_cast<float>(rng.uniform(-600, 600)), static_cast<float>(rng.uniform(-500, 500)),
                     static_cast<float>(rng.uniform(500, 1600)));
  return pts;
}

TEST(GlobalClusters, SameAsPcl) {
  for (uint64_t seed : {1, 2, 3, 4}) {
    std::vector<Vec3f> pts = blobs(seed);
    if (seed == 4)
      for (const Vec3f& p : blobs(5)) pts.push_back(p + Vec3f(20000.f, 20000.f, 0.f));
    for (double tol : {6.0, 11.0, 15.0, 24.0, 47.0, 130.0}) {
      for (auto [lo, hi] : {std::pair{1, 1000000}, std::pair{20, 150}}) {
        const auto ours = global::euclidean_clusters(pts, tol, lo, hi);
        const auto pcl = global::euclidean_clusters_pcl(pts, tol, lo, hi);
        EXPECT_EQ(ours, pcl) << "seed " << seed << " tolerance " << tol << " sizes " << lo << ".." << hi;
        if (tol == 15.0 && lo == 1) EXPECT_GT(ours.size(), 20u) << "components of every kind";
      }
    }
  }
}

TEST(GlobalClusters, NonFinitePointsAreInNoCluster) {
  std::vector<Vec3f> pts{{0, 0, 500}, {5, 0, 500}, {NAN, 0, 500}, {100, 0, 500}};
  const auto c = global::euclidean_clusters(pts, 10, 1, 100);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0], (std::vector<int>{0, 1}));
  EXPECT_EQ(c[1], (std::vector<int>{3}));
  EXPECT_TRUE(global::euclidean_clusters(pts, 0, 1, 100).empty());
}

}  // namespace
}  // namespace pb
