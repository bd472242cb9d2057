// The local pipeline's neighbourhoods (CloudNeighbours, recognition/local/
// internal.h): the sorted list is every finite point strictly within the
// radius, by (squared distance, index), whether a small cloud is scanned
// whole or a large one searched in its kd-tree; ties (duplicate points) by
// index; a point on the radius not listed; non-finite points never listed;
// a non-finite query lists nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/random.h"
#include "recognition/local/internal.h"

namespace {

using pb::Vec3f;
using Entries = std::vector<std::pair<float, int>>;

// The definition: the leaves' float distance x^2 + (y^2 + z^2) of p - q.
Entries reference(const std::vector<Vec3f>& pts, const Vec3f& q, float r2) {
  Entries out;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!pts[i].allFinite()) continue;
    const Vec3f d = pts[i] - q;
    const float s = d.x() * d.x() + (d.y() * d.y() + d.z() * d.z());
    if (s < r2) out.emplace_back(s, static_cast<int>(i));
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(CloudNeighbours, SortedListsAreTheDefinitionForSmallAndLargeClouds) {
  pb::Rng rng(3);
  for (const int n : {7, 500, 4096, 6000}) {  // scanned whole up to 4096 points, searched in the tree above
    std::vector<Vec3f> pts;
    for (int i = 0; i < n; ++i) {
      pts.emplace_back(static_cast<float>(rng.uniform(-100, 100)), static_cast<float>(rng.uniform(-100, 100)),
                       static_cast<float>(rng.uniform(900, 1100)));
      if (i % 50 == 7) pts.back().x() = std::numeric_limits<float>::quiet_NaN();
      if (i % 50 == 9 && i > 0) pts.back() = pts[static_cast<size_t>(i - 2)];  // a duplicate: a tie
    }
    if (n > 2) {  // a point exactly on the radius from another: strictly within lists it not
      pts[0] = Vec3f(10, 20, 1000);
      pts[1] = Vec3f(13, 24, 1000);
    }
    const pb::local::CloudNeighbours nb(pts);
    Entries got;
    if (n > 2) {
      nb.within(pts[0], 25.f, got);
      EXPECT_TRUE(std::none_of(got.begin(), got.end(), [](const auto& e) { return e.second == 1; })) << n;
      nb.within(pts[0], 25.0001f, got);
      EXPECT_TRUE(std::any_of(got.begin(), got.end(), [](const auto& e) { return e.second == 1; })) << n;
    }
    size_t listed = 0;
    for (int k = 0; k < 40; ++k) {
      const Vec3f q = pts[static_cast<size_t>(rng.uniform_int(0, n - 1))];
      if (!q.allFinite()) continue;
      for (const float r : {5.f, 30.f, 400.f}) {
        nb.within(q, r * r, got);
        ASSERT_EQ(got, reference(pts, q, r * r)) << n << " points, radius " << r;
        listed += got.size();
      }
    }
    EXPECT_GT(listed, static_cast<size_t>(n)) << "the lists are not all empty";
    nb.within(Vec3f(0, std::numeric_limits<float>::quiet_NaN(), 0), 1e6f, got);
    EXPECT_TRUE(got.empty());
  }
}

}  // namespace
