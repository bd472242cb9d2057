// GridNearest (recognition/grid_nearest.h) against KdTree3::nearest, which
// it replaces in ICP: the same index and the same squared distance, bit for
// bit, for every query. Clouds: random, a surface sampled on a lattice (many
// exact ties), duplicated points, non-finite points; queries near and far
// from the points, exactly on points and on cell borders; bounds of about
// one cell, zero, a point's exact distance (the bound is strict), infinite
// and NaN; hints valid, wrong, out of range, of non-finite points and none.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/random.h"
#include "recognition/grid_nearest.h"
#include "recognition/kdtree.h"

namespace {

using pb::Vec3f;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

struct Cloud {
  std::vector<Vec3f> points;
  double cell;
};

std::vector<Cloud> clouds() {
  pb::Rng rng(7);
  std::vector<Cloud> out;
  // Random points in a 0.2 m box (ICP's frame: metres), cell 18 mm.
  Cloud a{{}, 0.018};
  for (int i = 0; i < 3000; ++i)
    a.points.emplace_back(static_cast<float>(rng.uniform(-0.1, 0.1)), static_cast<float>(rng.uniform(-0.1, 0.1)),
                          static_cast<float>(rng.uniform(-0.1, 0.1)));
  out.push_back(a);
  // A tilted plane on a 10 mm lattice with every tenth point repeated, a
  // few non-finite points, cell 10 mm (points on cell borders; ties).
  Cloud b{{}, 0.01};
  for (int u = -15; u <= 15; ++u)
    for (int v = -15; v <= 15; ++v) {
      const Vec3f p(0.01f * static_cast<float>(u), 0.01f * static_cast<float>(v), 0.3f * 0.01f * static_cast<float>(u));
      b.points.push_back(p);
      if ((u + v) % 10 == 0) b.points.push_back(p);
    }
  b.points.emplace_back(kNaN, 0.f, 0.f);
  b.points.emplace_back(0.f, kInf, 0.f);
  out.push_back(b);
  // The same lattice in reverse order: the cells are scanned with the
  // higher of two tied indices first, so the lower-index rule decides.
  Cloud r{std::vector<Vec3f>(b.points.rbegin(), b.points.rend()), 0.01};
  out.push_back(r);
  // Millimetre coordinates around 1.3 m, cell 180 mm (the warehouse's
  // scale), and a cell far smaller than the spread (the grid enlarges it).
  Cloud c{{}, 180.0};
  for (int i = 0; i < 2000; ++i)
    c.points.emplace_back(static_cast<float>(rng.uniform(-900, 900)), static_cast<float>(rng.uniform(-900, 900)),
                          static_cast<float>(1300 + rng.uniform(-900, 900)));
  out.push_back(c);
  Cloud d{c.points, 1e-4};
  out.push_back(d);
  // A dense surface (a 2 mm lattice on a curved sheet) in cells of 50 mm:
  // hundreds of points per cell, so the kd-tree answers every query.
  Cloud e{{}, 50.0};
  for (int u = 0; u < 100; ++u)
    for (int v = 0; v < 100; ++v)
      e.points.emplace_back(2.f * static_cast<float>(u), 2.f * static_cast<float>(v),
                            static_cast<float>(0.002 * (u - 50) * (u - 50)));
  out.push_back(e);
  return out;
}

TEST(GridNearest, SameAnswersAsTheKdTree) {
  pb::Rng rng(11);
  int queries = 0, found = 0, ties = 0, gridless = 0, enlarged = 0;
  for (const Cloud& cl : clouds()) {
    const pb::KdTree3 tree(cl.points, 24);
    const pb::GridNearest grid(cl.points, cl.cell);
    gridless += !grid.has_grid();
    enlarged += grid.cell_side() > cl.cell;
    const int n = static_cast<int>(cl.points.size());
    const float c2 = static_cast<float>(cl.cell * cl.cell);
    for (int k = 0; k < 4000; ++k) {
      // A query: near a point, exactly on one, or anywhere around.
      const int base_index = rng.uniform_int(0, n - 1);
      const Vec3f& base = cl.points[static_cast<size_t>(base_index)];
      Vec3f q = base;
      const int kind = rng.uniform_int(0, 3);
      const double spread = kind == 0 ? 0.2 * cl.cell : kind == 1 ? 2 * cl.cell : 0.0;
      for (int a = 0; a < 3; ++a) q[a] += static_cast<float>(rng.uniform(-spread, spread));
      if (kind == 3) q = Vec3f(static_cast<float>(rng.uniform(-3, 3) * cl.cell * 10), 0.f, 0.f);
      if (!base.allFinite()) q = Vec3f(0.f, 0.f, 0.f);
      if (k % 500 == 0) q.x() = kNaN;
      // A bound: about a cell, zero, a point's exact distance, none, NaN.
      float bound = c2 * static_cast<float>(rng.uniform(0.5, 2.0));
      const int b = rng.uniform_int(0, 9);
      if (b == 0) bound = 0;
      if (b == 1) bound = (cl.points[static_cast<size_t>(rng.uniform_int(0, n - 1))] - q).squaredNorm();
      if (b == 2) bound = kInf;
      if (b == 3 && k % 7 == 0) bound = kNaN;
      // A hint: the nearest's neighbour, any point, out of range, none.
      int hint = -1;
      const int h = rng.uniform_int(0, 4);
      if (h == 0) hint = rng.uniform_int(0, n - 1);
      if (h == 1) hint = n + 3;
      if (h == 2) hint = tree.nearest(q, nullptr, kInf);
      if (h == 3) hint = rng.bernoulli(0.2) ? n - 1 : std::max(0, std::min(n - 1, base_index + (rng.bernoulli(0.5) ? 1 : 31) * (rng.bernoulli(0.5) ? 1 : -1)));  // non-finite, or a lattice neighbour
      float dt = 0, dg = 0;
      const int it = tree.nearest(q, &dt, bound, hint);
      const int ig = grid.nearest(q, &dg, bound, hint);
      ASSERT_EQ(ig, it) << "query " << k << " bound " << bound << " hint " << hint;
      ASSERT_EQ(std::memcmp(&dg, &dt, sizeof(float)), 0) << "query " << k;
      ++queries;
      if (it >= 0) {
        ++found;
        // A tie: another point at exactly the same distance.
        for (int j = 0; j < n; ++j)
          if (j != it && (cl.points[static_cast<size_t>(j)] - q).squaredNorm() == dt) {
            ++ties;
            break;
          }
      }
    }
  }
  EXPECT_EQ(queries, 24000);
  EXPECT_EQ(gridless, 1);  // the dense surface: the kd-tree alone
  EXPECT_EQ(enlarged, 1);  // the 0.1 um cells over 1.8 m
  EXPECT_GT(found, 8000);  // most queries find a point: the comparison is not vacuous
  EXPECT_GT(ties, 100);    // and exact ties (the lower index wins) are among them
}

TEST(GridNearest, EmptyAndNonFiniteClouds) {
  const pb::GridNearest empty(std::vector<Vec3f>{}, 1.0);
  float d = 0;
  EXPECT_EQ(empty.nearest(Vec3f(0, 0, 0), &d, kInf, 0), -1);
  EXPECT_EQ(d, kInf);
  const pb::GridNearest nan(std::vector<Vec3f>{Vec3f(kNaN, 0, 0), Vec3f(0, kInf, 0)}, 1.0);
  EXPECT_EQ(nan.nearest(Vec3f(0, 0, 0), &d, kInf, 1), -1);
  const pb::GridNearest one(std::vector<Vec3f>{Vec3f(kNaN, 0, 0), Vec3f(1, 2, 3)}, 0.5);
  EXPECT_EQ(one.nearest(Vec3f(1, 2, 3.25f), &d, 1.f), 1);
  EXPECT_EQ(d, 0.0625f);
  EXPECT_EQ(one.nearest(Vec3f(1, 2, 3.25f), &d, 0.0625f), -1);  // the bound is strict
}

}  // namespace
