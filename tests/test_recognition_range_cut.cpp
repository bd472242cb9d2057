// The range cut (recognition/preprocess/internal.h): the vector path keeps
// the pixels the one-pixel loop keeps, and both keep what the definition
// says and give the kept points' box, on bounds that are not floats,
// non-finite coordinates, dropped pixels and clouds whose size is no
// multiple of eight.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/random.h"
#include "recognition/preprocess/internal.h"

namespace {

using pb::OrganizedCloud;
using pb::PointSet;
using pb::Vec3f;

// The definition, one pixel at a time in double.
std::vector<int> kept(const OrganizedCloud& c, double lo, double hi, const std::vector<char>& drop) {
  std::vector<int> out;
  for (size_t i = 0; i < c.points.size(); ++i) {
    const Vec3f& p = c.points[i];
    if (p.allFinite() && static_cast<double>(p.z()) >= lo && static_cast<double>(p.z()) <= hi &&
        (drop.empty() || !drop[i]))
      out.push_back(static_cast<int>(i));
  }
  return out;
}

TEST(RangeCut, VectorAndScalarKeepTheSamePixels) {
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const double lo = 500.1, hi = 2999.9;  // neither is a float
  // z values right at and beside the bounds' nearest floats.
  const float zs[] = {static_cast<float>(lo), std::nextafter(static_cast<float>(lo), 0.f),
                      std::nextafter(static_cast<float>(lo), inf), static_cast<float>(hi),
                      std::nextafter(static_cast<float>(hi), 0.f), std::nextafter(static_cast<float>(hi), inf)};
  pb::Rng rng(7);
  for (const int n : {0, 5, 8, 16, 61, 1000, 4099}) {
    OrganizedCloud c;
    c.width = n;
    c.height = 1;
    std::vector<char> drop(static_cast<size_t>(n), 0);
    for (int i = 0; i < n; ++i) {
      Vec3f p(static_cast<float>(rng.uniform(-500, 500)), static_cast<float>(rng.uniform(-500, 500)),
              static_cast<float>(rng.uniform(400, 3100)));
      const int what = rng.uniform_int(0, 19);  // mostly plain points, in runs of eight and not
      if (what == 0) p.z() = zs[rng.uniform_int(0, 5)];
      if (what == 1) p[rng.uniform_int(0, 2)] = nan;
      if (what == 2) p[rng.uniform_int(0, 2)] = rng.uniform_int(0, 1) ? inf : -inf;
      if (what == 3) drop[static_cast<size_t>(i)] = 1;
      if (i % 100 < 50) p.z() = 1000.f + static_cast<float>(i % 7);  // long runs of kept pixels
      c.points.push_back(p);
    }
    for (const bool with_drop : {false, true}) {
      const std::vector<char> d = with_drop ? drop : std::vector<char>{};
      const std::vector<int> want = kept(c, lo, hi, d);
      for (const auto isa : {pb::detail::RangeCutIsa::best, pb::detail::RangeCutIsa::scalar}) {
        float box[6];
        const PointSet ps = pb::detail::range_cut(c, lo, hi, d, isa, box);
        ASSERT_EQ(ps.pixel, want) << "n " << n << " drop " << with_drop;
        // The box of the kept points (lo > hi when there is none).
        for (int a = 0; a < 3; ++a) {
          float l = std::numeric_limits<float>::infinity(), h = -l;
          for (const int px : want) {
            l = std::min(l, c.points[static_cast<size_t>(px)][a]);
            h = std::max(h, c.points[static_cast<size_t>(px)][a]);
          }
          EXPECT_EQ(box[a], l) << "n " << n << " axis " << a;
          EXPECT_EQ(box[3 + a], h) << "n " << n << " axis " << a;
        }
        ASSERT_EQ(ps.points.size(), want.size());
        for (size_t k = 0; k < want.size(); ++k)
          ASSERT_EQ(ps.points[k], c.points[static_cast<size_t>(want[k])]) << "n " << n << " point " << k;
        EXPECT_EQ(ps.source_width, n);
        EXPECT_EQ(ps.source_height, 1);
      }
    }
  }
}

TEST(RangeCut, InfiniteAndHugeBoundsKeepEveryFinitePixel) {
  OrganizedCloud c;
  c.width = 16;
  c.height = 1;
  for (int i = 0; i < 16; ++i) c.points.emplace_back(1.f, 2.f, i == 3 ? std::numeric_limits<float>::max() : 10.f * i);
  for (const double hi : {std::numeric_limits<double>::infinity(), 1e300}) {
    const PointSet ps = pb::detail::range_cut(c, -1e300, hi);
    EXPECT_EQ(ps.size(), 16u) << hi;
  }
  // A maximum below FLT_MAX drops the pixel at FLT_MAX, and only it.
  const PointSet ps = pb::detail::range_cut(c, 0.0, 1e38);
  ASSERT_EQ(ps.size(), 15u);
  for (const int px : ps.pixel) EXPECT_NE(px, 3);
  // Bounds beyond the floats: a minimum above every float keeps nothing, a
  // maximum below every float keeps nothing.
  EXPECT_EQ(pb::detail::range_cut(c, 1e300, std::numeric_limits<double>::infinity()).size(), 0u);
  EXPECT_EQ(pb::detail::range_cut(c, -std::numeric_limits<double>::infinity(), -1e300).size(), 0u);
}

}  // namespace
