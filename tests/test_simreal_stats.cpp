// The sim-to-real statistics (simreal/sensor_stats.h), the supporting plane
// (simreal/frames.h) and McNemar's exact test, on images whose answer is
// known by construction.
#include <gtest/gtest.h>

#include <cmath>

#include "core/random.h"
#include "render/renderer.h"
#include "simreal/frames.h"
#include "simreal/sensor_stats.h"
#include "test_render_util.h"

using namespace pb;

namespace {

// A box 1 m in front of a camera, rendered with normals: the truth.
RenderOutput box_truth(const Intrinsics& K) {
  static const Mesh box = pbtest::make_box(100, 80, 60);
  DepthRenderer r(K, RenderSettings{50, 20000, true, true});
  Pose T;
  T.t = Vec3(0, 0, 1000);
  return r.render({{&box, T, 0}});
}

}  // namespace

TEST(SimrealStats, GaussianNoiseGivesItsSpreadAndNoBias) {
  const Intrinsics K = Intrinsics::from_fov(320, 240, 50, 40);
  const RenderOutput truth = box_truth(K);
  DepthImage m = truth.depth;
  Rng rng(3);
  for (float& z : m.z)
    if (z > 0) z = static_cast<float>(z + 2.0 + rng.normal(0, 2.0));
  SensorStatsAccumulator acc;
  acc.add(m, truth, K, {7});
  const SensorStats s = acc.finish();
  ASSERT_GT(s.all.n, 3000);  // the box covers 4144 pixels
  EXPECT_EQ(s.all.missing, 0);
  EXPECT_NEAR(s.all.bias_mm, 2.0, 0.1);     // the offset is bias...
  EXPECT_NEAR(s.all.spread_mm, 2.0, 0.1);   // ...and the noise spread
  ASSERT_EQ(s.by_object.count(7), 1u);
  EXPECT_EQ(s.by_object.at(7).n, s.all.n);
  // The front face is seen head-on: its pixels fall in the first bins.
  EXPECT_GT(s.by_incidence[0].n + s.by_incidence[1].n + s.by_incidence[2].n + s.by_incidence[3].n, s.all.n / 2);
}

TEST(SimrealStats, MissingPixelsAndTheOutline) {
  const Intrinsics K = Intrinsics::from_fov(320, 240, 50, 40);
  const RenderOutput truth = box_truth(K);
  DepthImage m = truth.depth;
  // Background 500 mm behind the box; one in ten object pixels without depth.
  Rng rng(5);
  int dropped = 0, object = 0;
  for (size_t p = 0; p < m.z.size(); ++p) {
    if (truth.labels[p] < 0) {
      m.z[p] = 1500;
      continue;
    }
    ++object;
    if (rng.bernoulli(0.1)) m.z[p] = 0, ++dropped;
  }
  SensorStatsAccumulator acc;
  acc.add(m, truth, K, {1});
  const SensorStats s = acc.finish();
  EXPECT_EQ(s.all.n, object);
  EXPECT_EQ(s.all.missing, dropped);
  EXPECT_NEAR(s.all.missing_rate(), 0.1, 0.01);
  // Inside the outline the depth is the object's (unless dropped), outside
  // it is farther: a silhouette neither grown nor shrunk.
  for (const SilhouetteBin& b : s.silhouette) {
    if (b.n == 0) continue;
    if (b.d <= 0) EXPECT_NEAR(static_cast<double>(b.object + b.missing) / b.n, 1.0, 1e-12) << b.d;
    if (b.d > 0) EXPECT_EQ(b.farther, b.n) << b.d;
  }
}

TEST(SimrealStats, DistancesToTheOutline) {
  // A 5 x 5 object in a 9 x 9 image: its centre is 2 steps from its outline.
  const int W = 9, H = 9;
  std::vector<int32_t> labels(W * H, -1);
  for (int v = 2; v < 7; ++v)
    for (int u = 2; u < 7; ++u) labels[v * W + u] = 0;
  const std::vector<int> in = inside_edge_distance(labels, W, H, 100);
  EXPECT_EQ(in[4 * W + 4], 2);
  EXPECT_EQ(in[2 * W + 4], 0);
  EXPECT_EQ(in[0], -1);
  std::vector<int> out, nearest;
  outside_distance(labels, W, H, 3, out, nearest);
  EXPECT_EQ(out[1 * W + 4], 1);
  EXPECT_EQ(nearest[1 * W + 4], 2 * W + 4);
  EXPECT_EQ(out[1 * W + 1], 2);  // (1, 1): two steps to (2, 2)
  EXPECT_EQ(out[0], -1);         // (0, 0): four steps, beyond the cap
}

TEST(SimrealPlane, RansacFindsTheTable) {
  const Intrinsics K = Intrinsics::from_fov(320, 240, 60, 45);
  // A plane tilted 30 deg about x through (0, 0, 1200), with 2 mm noise.
  const Vec3 n = Vec3(0, -std::cos(M_PI / 6), -std::sin(M_PI / 6)).normalized();
  const double d = -n.dot(Vec3(0, 0, 1200));
  DepthImage m(K.width, K.height);
  Rng rng(11);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const Vec3 ray = K.backproject(u, v, 1.0);
      const double t = -d / n.dot(ray);
      if (t > 0) m.at(u, v) = static_cast<float>(t + rng.normal(0, 2.0));
    }
  const std::vector<int32_t> none(m.z.size(), -1);
  const SupportPlane p = fit_support_plane(m, none, K, 1);
  ASSERT_TRUE(p.found);
  EXPECT_GT(std::abs(p.n.dot(n)), 0.999);
  EXPECT_LT(p.n.z(), 0);  // towards the camera
  EXPECT_NEAR(std::abs(p.d), std::abs(d), 3.0);
  EXPECT_GT(p.inliers, 0.9 * p.candidates);
}
