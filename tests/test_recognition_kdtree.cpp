// The kd-tree against brute force: nearest (with the distance bound and the
// lower-index rule for ties) and radius queries on random and degenerate
// clouds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/random.h"
#include "recognition/kdtree.h"

namespace {

using pb::Vec3;
using pb::Vec3f;

std::vector<Vec3f> random_cloud(size_t n, uint64_t seed, float scale) {
  pb::Rng rng(seed);
  std::vector<Vec3f> v;
  for (size_t i = 0; i < n; ++i)
    v.emplace_back(static_cast<float>(rng.uniform(-scale, scale)), static_cast<float>(rng.uniform(-scale, scale)),
                   static_cast<float>(rng.uniform(-scale, scale)));
  return v;
}

int brute_nearest(const std::vector<Vec3f>& pts, const Vec3f& q, float max2, float* d2) {
  int best = -1;
  float bd = max2;
  for (size_t i = 0; i < pts.size(); ++i) {
    const float d = (pts[i] - q).squaredNorm();
    if (d < bd) {
      bd = d;
      best = static_cast<int>(i);
    }
  }
  *d2 = bd;
  return best;
}

TEST(KdTree3, NearestAndRadiusEqualBruteForce) {
  for (size_t n : {1u, 2u, 7u, 100u, 3000u}) {
    const auto pts = random_cloud(n, 5 + n, 100.f);
    const pb::KdTree3 tree(pts);
    ASSERT_EQ(tree.size(), n);
    const auto queries = random_cloud(300, 99, 130.f);
    for (const Vec3f& q : queries) {
      float d_tree = 0, d_brute = 0;
      EXPECT_EQ(tree.nearest(q, &d_tree), brute_nearest(pts, q, std::numeric_limits<float>::infinity(), &d_brute));
      EXPECT_EQ(d_tree, d_brute);
      const float max2 = 20.f * 20.f;  // bounded: -1 when nothing is closer
      EXPECT_EQ(tree.nearest(q, &d_tree, max2), brute_nearest(pts, q, max2, &d_brute));
      std::vector<int> got, want;
      tree.radius(q, 25.f, got);
      std::vector<std::pair<float, int>> all;
      for (size_t i = 0; i < pts.size(); ++i)
        if ((pts[i] - q).squaredNorm() <= 25.f * 25.f) all.emplace_back((pts[i] - q).squaredNorm(), static_cast<int>(i));
      std::sort(all.begin(), all.end());
      for (const auto& a : all) want.push_back(a.second);
      EXPECT_EQ(got, want);
    }
  }
}

TEST(KdTree3, DuplicatesResolveToTheLowestIndexAndEmptyTreesFindNothing) {
  std::vector<Vec3f> pts(50, Vec3f(1, 2, 3));
  pts.push_back(Vec3f(10, 0, 0));
  const pb::KdTree3 tree(pts);
  float d2 = -1;
  EXPECT_EQ(tree.nearest(Vec3f(1, 2, 3.5f), &d2), 0);
  EXPECT_FLOAT_EQ(d2, 0.25f);
  EXPECT_EQ(tree.nearest(Vec3f(9, 0, 0)), 50);
  const pb::KdTree3 empty(std::vector<Vec3f>{});
  EXPECT_EQ(empty.nearest(Vec3f(0, 0, 0), &d2), -1);
  EXPECT_EQ(tree.nearest(Vec3f(NAN, 0, 0)), -1);
  std::vector<int> out{7};
  empty.radius(Vec3f(0, 0, 0), 5, out);
  EXPECT_TRUE(out.empty());
}

// any_within answers "is any point below the bound" as nearest does (and
// returns such a point); any_preferred(q, i) is -1 exactly when nearest(q)
// is i: on random clouds, on a grid (many equal distances) and on
// duplicates, where the lower index is preferred.
TEST(KdTree3, AnyWithinAndAnyPreferredAnswerAsNearestDoes) {
  std::vector<std::vector<Vec3f>> clouds = {random_cloud(3000, 17, 100.f), random_cloud(9, 18, 100.f)};
  std::vector<Vec3f> grid;
  for (int x = 0; x < 12; ++x)
    for (int y = 0; y < 12; ++y)
      for (int z = 0; z < 12; ++z) grid.emplace_back(10.f * x, 10.f * y, 10.f * z);
  for (int k = 0; k < 40; ++k) grid.push_back(grid[static_cast<size_t>(k * 37)]);  // duplicates, higher index
  clouds.push_back(grid);
  for (const auto& pts : clouds) {
    const pb::KdTree3 tree(pts);
    auto queries = random_cloud(400, 23, 120.f);
    for (const Vec3f& p : pts) queries.push_back(p);  // on points: ties everywhere on the grid
    for (size_t qi = 0; qi < queries.size(); ++qi) {
      const Vec3f& q = queries[qi];
      for (const float max2 : {5.f * 5.f, 10.f * 10.f, 30.f * 30.f}) {
        float d = 0;
        const bool any = brute_nearest(pts, q, max2, &d) >= 0;
        const int hint = static_cast<int>(qi % pts.size());
        for (const int h : {-1, hint}) {
          const int got = tree.any_within(q, max2, h);
          ASSERT_EQ(got >= 0, any);
          if (got >= 0) EXPECT_LT((pts[static_cast<size_t>(got)] - q).squaredNorm(), max2);
        }
      }
      for (const int i : {static_cast<int>(qi % pts.size()), tree.nearest(q)}) {
        const int better = tree.any_preferred(q, i);
        EXPECT_EQ(better < 0, tree.nearest(q) == i) << "query " << qi << " point " << i;
        if (better >= 0) {
          const float di = (pts[static_cast<size_t>(i)] - q).squaredNorm();
          const float db = (pts[static_cast<size_t>(better)] - q).squaredNorm();
          EXPECT_TRUE(db < di || (db == di && better < i));
        }
      }
    }
  }
  const pb::KdTree3 empty(std::vector<Vec3f>{});
  EXPECT_EQ(empty.any_within(Vec3f(0, 0, 0), 1e9f), -1);
  EXPECT_EQ(empty.any_preferred(Vec3f(0, 0, 0), 0), -1);
}

// restricted: a tree cut down to a subset in shifted and scaled
// coordinates (refinement's crop in its local frame) answers as a tree
// built over that subset: nearest (index and distance, ties to the lower
// index), any_within, any_preferred, radius and the thinned neighbourhoods.
TEST(KdTree3, RestrictedTreeAnswersAsOneBuiltOverTheSubset) {
  std::vector<Vec3f> grid;  // duplicates and equal distances
  for (int x = 0; x < 15; ++x)
    for (int y = 0; y < 15; ++y)
      for (int z = 0; z < 6; ++z) grid.emplace_back(30.f * x - 200.f, 30.f * y, 800.f + 30.f * z);
  for (const auto& cam : {random_cloud(5000, 31, 1000.f), grid}) {
    const pb::KdTree3 whole(cam);
    const Vec3 c(12.3, -45.6, 789.0);
    const auto map = [&c](int a, float x) { return static_cast<float>((static_cast<double>(x) - c[a]) * 1e-3); };
    std::vector<size_t> keep;
    std::vector<Vec3f> local;
    for (size_t i = 0; i < cam.size(); ++i)
      if ((cam[i].cast<double>() - Vec3(0, 200, 900)).norm() < 400.0) {  // a ball, as refinement's crop
        keep.push_back(i);
        local.push_back(((cam[i].cast<double>() - c) * 1e-3).cast<float>());
      }
    ASSERT_GT(keep.size(), 50u);
    const pb::KdTree3 cut = whole.restricted(keep, local, map);
    const pb::KdTree3 built(local);
    ASSERT_EQ(cut.size(), local.size());
    auto queries = random_cloud(300, 37, 0.6f);
    for (const auto& p : local) queries.push_back(p);
    for (size_t qi = 0; qi < queries.size(); ++qi) {
      const Vec3f& q = queries[qi];
      float d_cut = 0, d_built = 0;
      ASSERT_EQ(cut.nearest(q, &d_cut), built.nearest(q, &d_built));
      EXPECT_EQ(d_cut, d_built);
      const float max2 = 0.05f * 0.05f;
      const int hint = static_cast<int>(qi % local.size());
      EXPECT_EQ(cut.nearest(q, nullptr, max2, hint), built.nearest(q, nullptr, max2, hint));
      EXPECT_EQ(cut.any_within(q, max2) >= 0, built.any_within(q, max2) >= 0);
      EXPECT_EQ(cut.any_preferred(q, hint) >= 0, built.any_preferred(q, hint) >= 0);
      std::vector<int> a, b;
      cut.radius(q, 0.08f, a);
      built.radius(q, 0.08f, b);
      EXPECT_EQ(a, b);
      std::vector<std::pair<float, int>> ta, tb;
      EXPECT_EQ(cut.within_thinned(q, 0.1f * 0.1f, 16, ta, pb::KdTree3::Thinning::counted),
                built.within_thinned(q, 0.1f * 0.1f, 16, tb, pb::KdTree3::Thinning::counted));
      std::sort(ta.begin(), ta.end());  // the same points chosen need not be: the orders differ
      EXPECT_EQ(ta.size(), tb.size());
    }
  }
  EXPECT_EQ(pb::KdTree3(random_cloud(10, 3, 1.f)).restricted({}, {}, [](int, float x) { return x; }).size(), 0u);
}

// radius_remaining reports radius_unsorted's points, in its order, without
// those removed from the Remaining set, as points are removed one by one
// (region growing's use); removing twice changes nothing.
TEST(KdTree3, RadiusRemainingIsRadiusUnsortedWithoutTheRemovedPoints) {
  for (const size_t n : {1u, 50u, 4000u}) {
    const auto pts = random_cloud(n, 41 + n, 100.f);
    const pb::KdTree3 tree(pts);
    pb::KdTree3::Remaining left(tree);
    std::vector<char> removed(n, 0);
    pb::Rng rng(7);
    const auto queries = random_cloud(200, 43, 110.f);
    for (size_t qi = 0; qi < queries.size(); ++qi) {
      for (int k = 0; k < 25; ++k) {  // remove a few, some twice
        const int i = static_cast<int>(rng.uniform(0.0, static_cast<double>(n) - 1e-9));
        left.remove(i);
        removed[static_cast<size_t>(i)] = 1;
      }
      std::vector<int> all, got, want;
      tree.radius_unsorted(queries[qi], 30.f, all);
      for (const int i : all)
        if (!removed[static_cast<size_t>(i)]) want.push_back(i);
      tree.radius_remaining(queries[qi], 30.f, left, got);
      ASSERT_EQ(got, want) << "n " << n << " query " << qi;
      for (size_t i = 0; i < n; ++i) ASSERT_EQ(left.has(static_cast<int>(i)), !removed[i]);
    }
  }
}

// within: strictly below the bound (a point exactly at it is left out, as
// FLANN's radius search), sorted by (distance, index) with duplicates
// (equal distances) in index order; unsorted: the same set; scanned
// (within_scanned): the same list.
TEST(KdTree3, WithinIsStrictAndSortedByDistanceThenIndex) {
  std::vector<Vec3f> pts = random_cloud(3000, 11, 100.f);
  for (int i = 0; i < 40; ++i) pts.push_back(pts[static_cast<size_t>(i) * 7]);  // exact duplicates
  pts.push_back(Vec3f(3, 4, 0));  // exactly 5 from the origin
  const pb::KdTree3 tree(pts);
  pb::Rng rng(12);
  std::vector<Vec3f> queries{Vec3f(0, 0, 0)};
  for (int i = 0; i < 100; ++i) queries.push_back(pts[static_cast<size_t>(rng.uniform_int(0, 2999))]);
  for (const Vec3f& q : queries) {
    for (float max2 : {25.f, 400.f, 900.f}) {
      std::vector<std::pair<float, int>> want;
      for (size_t i = 0; i < pts.size(); ++i) {
        const float d = (pts[i] - q).squaredNorm();
        if (d < max2) want.emplace_back(d, static_cast<int>(i));
      }
      std::sort(want.begin(), want.end());
      std::vector<std::pair<float, int>> got;
      tree.within(q, max2, got);
      EXPECT_EQ(got, want);
      tree.within_scanned(q, max2, got);
      EXPECT_EQ(got, want) << "scanned";
      tree.within(q, max2, got, false);
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, want);
    }
  }
  std::vector<std::pair<float, int>> at_bound;
  tree.within(Vec3f(0, 0, 0), 25.f, at_bound);
  for (const auto& e : at_bound) EXPECT_NE(e.second, static_cast<int>(pts.size()) - 1) << "25 is not below 25";
  tree.within_scanned(Vec3f(0, 0, 0), 25.f, at_bound);
  for (const auto& e : at_bound) EXPECT_NE(e.second, static_cast<int>(pts.size()) - 1) << "scanned: 25 is not below 25";
}

// Long neighbourhoods (thousands of points: the bucket-sorted path, buckets
// of many equal distances too) come in the same order as short ones: by
// distance, equal distances by index.
TEST(KdTree3, LongNeighbourhoodsAreSortedByDistanceThenIndex) {
  std::vector<Vec3f> pts = random_cloud(6000, 21, 50.f);
  for (int i = 0; i < 300; ++i) pts.push_back(pts[static_cast<size_t>(i) * 11]);  // equal distances
  for (int i = 0; i < 200; ++i) pts.emplace_back(0.f, 0.f, static_cast<float>(i % 7));  // more ties
  const pb::KdTree3 tree(pts);
  for (const Vec3f& q : {Vec3f(0, 0, 0), Vec3f(10, -5, 3), pts[17]}) {
    for (float max2 : {2500.f, 1e6f}) {
      std::vector<std::pair<float, int>> want;
      for (size_t i = 0; i < pts.size(); ++i) {
        const float d = (pts[i] - q).squaredNorm();
        if (d < max2) want.emplace_back(d, static_cast<int>(i));
      }
      std::sort(want.begin(), want.end());
      ASSERT_GT(want.size(), 512u);  // long enough for the bucket sort
      std::vector<std::pair<float, int>> got;
      tree.within(q, max2, got);
      EXPECT_EQ(got, want);
      tree.within_scanned(q, max2, got);
      EXPECT_EQ(got, want) << "scanned";
    }
  }
}

// sort_entries (FPFH's thinned supports) orders as std::sort: random lists
// of every length from 0 to 199 and of about 200 to 1200 (short ones by
// std::sort, long ones by buckets), with equal distances, zeros and one
// distance for all.
TEST(KdTree3, SortEntriesEqualsStdSort) {
  std::mt19937 rng(23);
  for (int t = 0; t < 300; ++t) {
    const size_t n = static_cast<size_t>(t < 200 ? t : 200 + 10 * (t - 200) + static_cast<int>(rng() % 7));
    std::uniform_real_distribution<float> d(0.f, t % 3 == 0 ? 4.f : 2500.f);
    std::vector<std::pair<float, int>> entries(n);
    for (size_t k = 0; k < n; ++k) {
      const int kind = static_cast<int>(rng() % 10);
      const float v = t % 50 == 7 ? 9.f : kind == 0 ? 0.f : kind == 1 ? std::floor(d(rng)) : d(rng);
      entries[k] = {v, static_cast<int>(rng() % 100000)};
    }
    std::vector<std::pair<float, int>> want = entries;
    std::sort(want.begin(), want.end());
    pb::KdTree3::sort_entries(entries);
    ASSERT_EQ(entries, want) << "list " << t << " of " << n;
  }
}

// The thinned search gives what the full one gives after keep_evenly, entry
// for entry and in order, with the full count: random clouds, a surface
// (a plane's grid, where whole subtrees lie inside the ball), duplicates,
// points exactly at the radius, every thinning from none to beyond the count.
TEST(KdTree3, ThinnedSearchesEqualTheFullOnesThinned) {
  pb::Rng rng(5);
  std::vector<std::vector<Vec3f>> clouds = {random_cloud(5000, 3, 200.f), random_cloud(37, 4, 10.f)};
  std::vector<Vec3f> grid;
  for (int i = 0; i < 120; ++i)
    for (int j = 0; j < 120; ++j) grid.emplace_back(2.5f * static_cast<float>(i), 2.5f * static_cast<float>(j), 700.f);
  for (int i = 0; i < 400; ++i) grid.push_back(grid[static_cast<size_t>(i) * 29]);  // duplicates
  clouds.push_back(grid);
  size_t compared = 0, thinned = 0;
  for (const auto& pts : clouds) {
    const pb::KdTree3 tree(pts);
    for (int t = 0; t < 60; ++t) {
      auto any_point = [&] { return pts[static_cast<size_t>(rng.uniform_int(0, static_cast<int>(pts.size()) - 1))]; };
      const Vec3f q = t % 3 == 0 ? any_point()
                                 : Vec3f(static_cast<float>(rng.uniform(-50, 300)),
                                         static_cast<float>(rng.uniform(-50, 300)),
                                         static_cast<float>(rng.uniform(-50, 800)));
      // A radius exactly at some point's distance (the bound's edge) or random.
      const float edge = (any_point() - q).squaredNorm();
      for (const float r2 : {edge, static_cast<float>(rng.uniform(1, 40000)), 1e9f}) {
        for (const int max_points : {0, 1, 5, 64, 256, 100000}) {
          std::vector<std::pair<float, int>> full, got;
          tree.within(q, r2, full, false);
          const size_t n = full.size();
          pb::keep_evenly(full, max_points);
          using How = pb::KdTree3::Thinning;
          for (const How how : {How::counted, How::point_by_point, How::automatic}) {
            EXPECT_EQ(tree.within_thinned(q, r2, max_points, got, how), n);
            ASSERT_EQ(got, full) << "within, r2 " << r2 << " max " << max_points << " way " << static_cast<int>(how);
          }
          ++compared;
          thinned += max_points > 0 && n > static_cast<size_t>(max_points);
        }
      }
    }
  }
  EXPECT_GT(thinned, 500u);
  EXPECT_GT(compared, 3000u);
  // Empty tree, non-finite query, no radius: nothing.
  std::vector<std::pair<float, int>> out{{1.f, 1}};
  for (const auto how : {pb::KdTree3::Thinning::counted, pb::KdTree3::Thinning::point_by_point}) {
    EXPECT_EQ(pb::KdTree3().within_thinned(Vec3f(0, 0, 0), 1.f, 5, out, how), 0u);
    EXPECT_TRUE(out.empty());
    const pb::KdTree3 tree(grid);
    EXPECT_EQ(tree.within_thinned(Vec3f(std::nanf(""), 0, 0), 1e6f, 5, out, how), 0u);
    EXPECT_EQ(tree.within_thinned(grid[0], 0.f, 5, out, how), 0u);
  }
}

}  // namespace
