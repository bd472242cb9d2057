// Noise models: measured Gaussian sigma, structured-light error growth with
// depth and projector shadows, time-of-flight flying pixels only at depth
// edges, grazing angles, ranges, seeding, and the structured-light model
// against its definition bit for bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/rotation.h"
#include "render/sensor.h"
#include "render/window_sums.h"
#include "test_render_util.h"

using namespace pb;

namespace {

struct Scene {
  Mesh wall, box;
  std::vector<RenderItem> items;
};

RenderOutput render_plane(const Intrinsics& K, double z, double tilt_deg, const Vec3& axis = Vec3(0, 1, 0)) {
  DepthRenderer r(K, RenderSettings{50, 20000, true, true});
  const Mesh quad = pbtest::make_quad(static_cast<float>(3 * z));
  Pose T;
  T.R = axis_angle(axis.normalized(), tilt_deg * M_PI / 180.0);
  T.t = Vec3(0, 0, z);
  return r.render({{&quad, T, 1}});
}

// A 200 x 200 x 100 mm box (front face at z = 750) before a wall at 1200 mm.
RenderOutput render_box_wall(const Intrinsics& K) {
  DepthRenderer r(K, RenderSettings{50, 20000, true, true});
  const Mesh wall = pbtest::make_quad(3000.f);
  const Mesh box = pbtest::make_box(100, 100, 50);
  Pose Tw, Tb;
  Tw.t = Vec3(0, 0, 1200);
  Tb.t = Vec3(0, 0, 800);
  return r.render({{&wall, Tw, 1}, {&box, Tb, 2}});
}

struct Stats {
  double mean = 0, std = 0, rms = 0;
  size_t n = 0;
};

Stats error_stats(const DepthImage& noisy, const DepthImage& truth) {
  Stats s;
  double sum = 0, sum2 = 0;
  for (size_t i = 0; i < noisy.z.size(); ++i)
    if (noisy.z[i] > 0 && truth.z[i] > 0) {
      const double e = double(noisy.z[i]) - truth.z[i];
      sum += e;
      sum2 += e * e;
      ++s.n;
    }
  s.mean = sum / s.n;
  s.rms = std::sqrt(sum2 / s.n);
  s.std = std::sqrt(std::max(0.0, sum2 / s.n - s.mean * s.mean));
  return s;
}

DepthImage noisy(const RenderOutput& out, const SensorProfile& sensor, const NoiseSettings& noise, uint64_t seed) {
  DepthImage d = out.depth;
  Rng rng(seed);
  apply_noise(d, out, sensor, noise, rng);
  return d;
}

}  // namespace

TEST(RenderNoise, GaussianSigmaWithinFivePercent) {
  const SensorProfile synth = sensor_profile("synthetic");
  const RenderOutput out = render_plane(synth.K, 1000, 25);
  ASSERT_EQ(out.depth.valid_count(), static_cast<size_t>(512 * 512));
  for (double sigma : {1.0, 2.5}) {
    NoiseSettings n = synth.noise;
    n.gaussian.sigma_mm = sigma;
    const Stats s = error_stats(noisy(out, synth, n, 42), out.depth);
    std::printf("gaussian sigma %.2f: measured %.4f mm (mean %.4f) over %zu pixels\n", sigma, s.std, s.mean, s.n);
    EXPECT_EQ(s.n, out.depth.valid_count());
    EXPECT_NEAR(s.std, sigma, 0.05 * sigma);
    EXPECT_NEAR(s.mean, 0.0, 0.05 * sigma);
  }
}

TEST(RenderNoise, StructuredLightErrorGrowsWithDepth) {
  const SensorProfile astra = sensor_profile("astra");
  ASSERT_EQ(astra.noise.model, "structured_light");
  std::vector<double> rms;
  for (double z : {800.0, 2500.0}) {
    const RenderOutput out = render_plane(astra.K, z, 30);
    const DepthImage d = noisy(out, astra, astra.noise, 7);
    const Stats s = error_stats(d, out.depth);
    std::printf("astra z=%.0f: error rms %.3f mm, std %.3f mm, mean %.3f mm, %zu of %zu pixels kept\n", z, s.rms,
                s.std, s.mean, s.n, out.depth.valid_count());
    EXPECT_GT(s.n, 0.95 * out.depth.valid_count());  // a plane: no shadows, no grazing
    rms.push_back(s.rms);
  }
  // Error ~ z^2 / (fx b): (2500/800)^2 = 9.8; require clear growth. At
  // 800 mm: 0.69 px of jitter over a 3 x 3 window is about 3.5 mm.
  EXPECT_GT(rms[1], 5.0 * rms[0]);
  EXPECT_LT(rms[0], 5.0);
}

TEST(RenderNoise, StructuredLightQuantizesDisparity) {
  // Without jitter and smoothing, every depth is fx b / (k * step).
  SensorProfile astra = sensor_profile("astra");
  NoiseSettings n = astra.noise;
  n.structured_light.disparity_sigma_px = 0;
  n.structured_light.smoothing_radius_px = 0;
  const RenderOutput out = render_plane(astra.K, 1500, 40);
  const DepthImage d = noisy(out, astra, n, 1);
  const double fb = astra.K.fx * n.structured_light.baseline_mm;
  size_t checked = 0;
  for (size_t i = 0; i < d.z.size(); ++i)
    if (d.z[i] > 0) {
      const double k = fb / d.z[i] / n.structured_light.disparity_step_px;
      EXPECT_NEAR(k, std::round(k), 1e-3);
      // rounding the disparity moves the depth by at most half a step
      const double dz = std::abs(fb / out.depth.z[i] - fb / d.z[i]);
      EXPECT_LE(dz, 0.5 * n.structured_light.disparity_step_px + 1e-6);
      ++checked;
    }
  EXPECT_GT(checked, 100000u);
}

// The structured-light model by its definition, pixel by pixel (sensor.h):
// measured pixels (valid, not grazing, not in the projector's shadow) get
// disparity fb / z plus one normal draw each in row-major order; each is
// then the mean over its window of the measured pixels whose true disparity
// lies within smoothing_edge_px of its own, rounded to the disparity step.
DepthImage structured_light_by_definition(const RenderOutput& out, const SensorProfile& sensor,
                                          const StructuredLightNoise& s, uint64_t seed) {
  const Intrinsics& K = sensor.K;
  const int W = K.width, H = K.height;
  const size_t N = static_cast<size_t>(W) * H;
  const double fb = K.fx * s.baseline_mm;
  const std::vector<uint8_t> shadow = projector_shadow_mask(out.depth, K, s.baseline_mm);
  const double cos_max = std::cos(s.max_incidence_deg * M_PI / 180.0);
  std::vector<uint8_t> ok(N, 0);
  std::vector<double> d_true(N, 0.0), d_noisy(N, 0.0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t px = static_cast<size_t>(v) * W + u;
      const float z = out.depth.z[px];
      if (!(z > 0.f && std::isfinite(z))) continue;
      const Vec3 n = out.normals[px].cast<double>();
      const Vec3 ray = Vec3((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0).normalized();
      const bool grazing = n.squaredNorm() >= 1e-12 && std::abs(n.normalized().dot(ray)) < cos_max;
      ok[px] = !grazing && !(s.shadows && shadow[px]);
      d_true[px] = fb / z;
    }
  Rng rng(seed);
  for (size_t px = 0; px < N; ++px)
    if (ok[px]) d_noisy[px] = d_true[px] + rng.normal(0.0, s.disparity_sigma_px);
  DepthImage d(W, H);
  const int r = s.smoothing_radius_px;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t px = static_cast<size_t>(v) * W + u;
      if (!ok[px]) continue;
      double sum = 0;
      int count = 0;
      for (int vv = std::max(0, v - r); vv <= std::min(H - 1, v + r); ++vv)
        for (int uu = std::max(0, u - r); uu <= std::min(W - 1, u + r); ++uu) {
          const size_t q = static_cast<size_t>(vv) * W + uu;
          if (ok[q] && std::abs(d_true[q] - d_true[px]) <= s.smoothing_edge_px) {
            sum += d_noisy[q];
            ++count;
          }
        }
      const double dq = std::round(sum / count / s.disparity_step_px) * s.disparity_step_px;
      const float z = dq > 0 ? static_cast<float>(fb / dq) : 0.f;
      d.z[px] = z < sensor.min_range_mm || z > sensor.max_range_mm ? 0.f : z;
    }
  return d;
}

TEST(RenderNoise, StructuredLightEqualsItsDefinitionBitForBit) {
  // The generator's version sums several pixels' windows side by side; every
  // depth must be the plain definition's, on the Astra frame and on frames
  // narrower than a block of windows, for several window sizes, with and
  // without the edge test (an infinite edge).
  const SensorProfile astra = sensor_profile("astra");
  std::vector<SensorProfile> sensors{astra};
  for (int width : {3, 7, 13}) {
    sensors.push_back(astra);
    sensors.back().K = Intrinsics::from_fov(width, 9, 60, 45);
  }
  // The Astra frame also as a plane tilted by a grazing limit about the
  // vertical axis: its pixels' incidence angles straddle the limit, some
  // within a hair of it (the grazing test's exact fallback). The fitted
  // astra keeps every angle; the model is tested at an 80 deg limit.
  const double kGrazingLimit = 80.0;
  sensors.push_back(astra);
  for (size_t i = 0; i < sensors.size(); ++i) {
    const SensorProfile& sensor = sensors[i];
    const RenderOutput out = i + 1 < sensors.size()
                                 ? render_box_wall(sensor.K)
                                 : render_plane(sensor.K, 1000, kGrazingLimit);
    for (int r : {0, 1, 2, 3})
      for (double edge : {astra.noise.structured_light.smoothing_edge_px, HUGE_VAL}) {  // inf: no edge awareness
        NoiseSettings n = astra.noise;
        n.structured_light.smoothing_radius_px = r;
        n.structured_light.smoothing_edge_px = edge;
        // The edge effects come after this part of the model
        // (StructuredLightEdgeEffects tests them).
        n.structured_light.edge_bleed_px = 0;
        n.structured_light.edge_dropout_rate = 0;
        n.structured_light.max_incidence_deg = kGrazingLimit;
        const DepthImage got = noisy(out, sensor, n, 7);
        const DepthImage want = structured_light_by_definition(out, sensor, n.structured_light, 7);
        size_t differ = 0, measured = 0, rendered = 0;
        for (size_t i = 0; i < got.z.size(); ++i) {
          differ += std::memcmp(&got.z[i], &want.z[i], sizeof(float)) != 0;
          measured += want.z[i] > 0;
          rendered += out.depth.z[i] > 0;
        }
        EXPECT_EQ(differ, 0u) << sensor.K.width << " px wide, radius " << r << ", edge " << edge;
        if (i + 1 < sensors.size()) {
          EXPECT_GT(measured, got.z.size() / 4) << sensor.K.width << " px wide, radius " << r << ", edge " << edge;
        } else {  // the tilted plane: both sides of the limit
          EXPECT_GT(measured, rendered / 10) << "radius " << r << ", edge " << edge;
          EXPECT_LT(measured, rendered * 9 / 10) << "radius " << r << ", edge " << edge;
        }
      }
  }
}

TEST(RenderNoise, StructuredLightEdgeEffects) {
  // The box before the wall, no jitter, smoothing or shadows: only the edge
  // effects move depths.
  SensorProfile astra = sensor_profile("astra");
  const RenderOutput out = render_box_wall(astra.K);
  NoiseSettings n = astra.noise;
  auto& s = n.structured_light;
  s.disparity_sigma_px = 0, s.smoothing_radius_px = 0, s.shadows = false, s.max_incidence_deg = 90;
  s.disparity_step_px = 1e-4;
  const int W = astra.K.width, H = astra.K.height;
  // Chebyshev distance of each wall pixel to the box (up to 6).
  std::vector<int> to_box(out.labels.size(), 99);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      if (out.labels[static_cast<size_t>(v) * W + u] != 1) continue;
      for (int dv = -6; dv <= 6; ++dv)
        for (int du = -6; du <= 6; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= W || vv >= H || out.labels[static_cast<size_t>(vv) * W + uu] != 2) continue;
          int& d = to_box[static_cast<size_t>(v) * W + u];
          d = std::min(d, std::max(std::abs(du), std::abs(dv)));
        }
    }
  // The box grows over the wall by exactly 2 px.
  s.edge_bleed_px = 2, s.edge_dropout_rate = 0;
  DepthImage d = noisy(out, astra, n, 9);
  size_t grown = 0, near_wall = 0;
  for (size_t p = 0; p < d.z.size(); ++p) {
    if (out.labels[p] != 1) continue;
    const bool like_box = d.z[p] > 0 && d.z[p] < 1000;
    if (to_box[p] <= 2) {
      EXPECT_TRUE(like_box) << p;
      ++grown;
    } else {
      EXPECT_FALSE(like_box) << p;
      near_wall += to_box[p] <= 6;
    }
  }
  EXPECT_GT(grown, 1000u);
  EXPECT_GT(near_wall, 1000u);
  // Rate 1 at the edge, falling off with distance: every pixel next to the
  // outline is dropped, none farther than 4 edge widths.
  s.edge_bleed_px = 0, s.edge_dropout_rate = 1, s.edge_dropout_px = 1;
  d = noisy(out, astra, n, 9);
  size_t edge_px = 0, kept_far = 0, far = 0;
  const auto box = [&](size_t q) { return out.labels[q] == 2; };
  for (size_t p = 0; p < d.z.size(); ++p) {
    if (out.labels[p] != 1) continue;
    const int u = static_cast<int>(p % W), v = static_cast<int>(p / W);
    const bool outline = (u > 0 && box(p - 1)) || (u + 1 < W && box(p + 1)) || (v > 0 && box(p - W)) ||
                         (v + 1 < H && box(p + W));
    if (outline) {  // next to the box: an edge pixel
      EXPECT_EQ(d.z[p], 0.f);
      ++edge_px;
    }
    if (to_box[p] >= 6 && to_box[p] < 99) ++far, kept_far += d.z[p] > 0;
  }
  EXPECT_GT(edge_px, 500u);
  EXPECT_EQ(kept_far, far);
}

TEST(RenderNoise, WindowSumKernelsAgreeBitForBit) {
  // The kernel the CPU picks (AVX2 where present) and SSE2 give the same
  // sums and counts, bit for bit, on random disparities with unmeasured
  // (+inf) pixels; the test above holds the picked one to the definition.
  const int W = 61, H = 7;
  Rng rng(3);
  std::vector<double> d_cmp(static_cast<size_t>(W) * H), d_noisy(d_cmp.size());
  for (size_t i = 0; i < d_cmp.size(); ++i) {
    const bool measured = rng.uniform() < 0.8;
    d_cmp[i] = measured ? 40.0 + rng.uniform(0.0, 3.0) : HUGE_VAL;
    d_noisy[i] = measured ? d_cmp[i] + rng.normal(0.0, 0.3) : 0.0;
  }
  for (int r : {0, 1, 2, 3})
    for (double edge : {1.0, HUGE_VAL}) {
      const WindowSumRow row{d_cmp.data(), d_noisy.data(), 3 * static_cast<size_t>(W), W, 3 - r, 3 + r, r, edge};
      std::vector<double> s_best(W, -1.0), n_best(W, -1.0), s_sse(W, -1.0), n_sse(W, -1.0);
      const int end_best = window_sums(row, r, s_best.data(), n_best.data());
      const int end_sse = window_sums(row, r, s_sse.data(), n_sse.data(), WindowSumIsa::sse2);
      EXPECT_EQ(end_best, end_sse);
      EXPECT_GE(end_best, W - r - 3);  // every column whose window fits a kernel step
      EXPECT_EQ(std::memcmp(s_best.data(), s_sse.data(), W * sizeof(double)), 0) << "radius " << r;
      EXPECT_EQ(std::memcmp(n_best.data(), n_sse.data(), W * sizeof(double)), 0) << "radius " << r;
    }
}

TEST(RenderNoise, DepthsFromSumsSameBitsAsOneAtATime) {
  // The depths of a row from its window sums, the picked kernel (AVX2
  // where present) against the one-pixel path: disparities on exact
  // halves of the step (both signs), near them, negative, beyond 2^52 and
  // NaN, with pixels not measured in between.
  const double step = 0.125, fb = 40000.0;
  std::vector<double> sum, count;
  std::vector<uint8_t> ok;
  Rng rng(5);
  const double specials[] = {2.5 * step, -2.5 * step, 3.5 * step, std::nextafter(2.5 * step, 0.0),
                             -7.0, 0.0, 1e17, std::nan(""), 0.5 * step, -0.5 * step};
  for (double x : specials) {
    sum.push_back(x), count.push_back(1.0), ok.push_back(1);
  }
  for (int i = 0; i < 203; ++i) {
    const double n = 1 + rng.uniform_int(0, 24);
    sum.push_back(n * rng.uniform(-1.0, 60.0)), count.push_back(n), ok.push_back(rng.uniform() < 0.9);
  }
  const int W = static_cast<int>(sum.size());
  for (int begin : {0, 1, 3}) {
    std::vector<float> best(W, -1.f), plain(W, -1.f);
    depths_from_sums(sum.data(), count.data(), ok.data(), begin, W, step, fb, best.data());
    depths_from_sums(sum.data(), count.data(), ok.data(), begin, W, step, fb, plain.data(), WindowSumIsa::sse2);
    EXPECT_EQ(std::memcmp(best.data(), plain.data(), W * sizeof(float)), 0) << "from column " << begin;
    if (begin > 0) EXPECT_EQ(best[begin - 1], -1.f);  // columns before `begin` untouched
  }
  std::vector<float> z(W);
  depths_from_sums(sum.data(), count.data(), ok.data(), 0, W, step, fb, z.data());
  EXPECT_EQ(z[0], static_cast<float>(fb / (3 * step)));  // 2.5 steps round up to 3
  EXPECT_EQ(z[2], static_cast<float>(fb / (4 * step)));
  EXPECT_EQ(z[3], static_cast<float>(fb / (2 * step)));  // just under a half rounds down
  EXPECT_EQ(z[1], 0.f);                                   // negative disparity: no depth
}

TEST(RenderNoise, ProjectorShadowsLieLeftOfTheBox) {
  const SensorProfile astra = sensor_profile("astra");
  const Intrinsics& K = astra.K;
  const RenderOutput out = render_box_wall(K);
  // The edge effects would drop pixels right of the box too.
  NoiseSettings n = astra.noise;
  n.structured_light.edge_dropout_rate = 0;
  n.structured_light.edge_bleed_px = 0;
  const DepthImage d = noisy(out, astra, n, 3);
  const double b = astra.noise.structured_light.baseline_mm;
  const double expected = K.fx * b * (1.0 / 750.0 - 1.0 / 1200.0);  // disparity difference, px
  const std::vector<uint8_t> mask = projector_shadow_mask(out.depth, K, b);
  int rows = 0;
  double left_sum = 0, mask_sum = 0;
  int right_max = 0;
  for (int v = 0; v < K.height; ++v) {
    // Box columns in this row from the labels.
    int u0 = -1, u1 = -1;
    for (int u = 0; u < K.width; ++u)
      if (out.labels[static_cast<size_t>(v) * K.width + u] == 2) {
        if (u0 < 0) u0 = u;
        u1 = u;
      }
    if (u0 < 0) {
      // Rows without the box: the wall is fully lit.
      for (int u = 0; u < K.width; ++u) EXPECT_EQ(mask[static_cast<size_t>(v) * K.width + u], 0);
      continue;
    }
    ++rows;
    int left = 0, right = 0, left_mask = 0;
    for (int u = std::max(0, u0 - 40); u < u0; ++u) {
      left += d.at(u, v) == 0.f;
      left_mask += mask[static_cast<size_t>(v) * K.width + u];
    }
    for (int u = u1 + 1; u <= std::min(K.width - 1, u1 + 40); ++u) right += d.at(u, v) == 0.f;
    for (int u = u0; u <= u1; ++u) EXPECT_EQ(mask[static_cast<size_t>(v) * K.width + u], 0);  // the box is lit
    EXPECT_NEAR(left_mask, expected, 1.0);
    left_sum += left;
    mask_sum += left_mask;
    right_max = std::max(right_max, right);
  }
  std::printf("shadow: %d rows, mean width left %.2f px (mask %.2f, expected %.2f), right max %d px\n", rows,
              left_sum / rows, mask_sum / rows, expected, right_max);
  EXPECT_GT(rows, 100);
  EXPECT_NEAR(left_sum / rows, expected, 1.5);
  EXPECT_EQ(right_max, 0);
}

// Time-of-flight pixels of the box-before-wall scene (a 450 mm jump), counted
// against the noise-free depth.
struct TofCounts {
  size_t edge_pixels = 0;  // an 8-neighbour across a jump larger than edge_jump_mm
  size_t flying = 0;       // valid, farther than 6 sigma from every true surface within 2 px
  size_t flying_far = 0;   // of those, farther than 1 px from an edge
  size_t flying_mid = 0;   // of those, more than edge_filter_close_mm + 6 sigma from the nearest and more than
                           // edge_filter_far_mm + 6 sigma from the farthest true depth within 2 px
  size_t interior = 0;     // true depth, farther than 3 px from an edge
  size_t interior_missing = 0;
  double normalized_std = 0;  // interior error / sigma
};

TofCounts count_tof(const NoiseSettings& noise) {
  const SensorProfile kin = sensor_profile("kinect_one");
  const Intrinsics& K = kin.K;
  const TimeOfFlightNoise& t = noise.tof;
  const RenderOutput out = render_box_wall(K);
  const DepthImage& truth = out.depth;
  const DepthImage d = noisy(out, kin, noise, 11);
  auto sigma = [&](double z) { return t.sigma_base_mm + t.sigma_per_m2_mm * (z / 1000) * (z / 1000); };
  auto edge_distance = [&](int u, int v) {
    int best = 1000;
    for (int dv = -3; dv <= 3; ++dv)
      for (int du = -3; du <= 3; ++du) {
        const int uu = u + du, vv = v + dv;
        if (uu < 1 || vv < 1 || uu >= K.width - 1 || vv >= K.height - 1) continue;
        for (int a = -1; a <= 1; ++a)
          for (int c = -1; c <= 1; ++c)
            if (std::abs(truth.at(uu + a, vv + c) - truth.at(uu, vv)) > t.edge_jump_mm)
              best = std::min(best, std::max(std::abs(du), std::abs(dv)));
      }
    return best;
  };
  TofCounts c;
  double sum2 = 0;
  size_t n2 = 0;
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const float z = d.at(u, v);
      const float z0 = truth.at(u, v);
      const int e = edge_distance(u, v);
      if (e == 0) ++c.edge_pixels;
      if (e > 3 && z0 > 0) {
        ++c.interior;
        if (z <= 0) ++c.interior_missing;
      }
      if (z <= 0) continue;
      bool far_from_all = true;
      float lo = 1e9f, hi = 0.f;
      for (int dv = -2; dv <= 2; ++dv)
        for (int du = -2; du <= 2; ++du) {
          const int uu = std::clamp(u + du, 0, K.width - 1), vv = std::clamp(v + dv, 0, K.height - 1);
          const float zt = truth.at(uu, vv);
          if (zt <= 0) continue;
          lo = std::min(lo, zt);
          hi = std::max(hi, zt);
          if (std::abs(z - zt) <= 6 * sigma(zt)) far_from_all = false;
        }
      if (far_from_all) {
        ++c.flying;
        if (e > 1) ++c.flying_far;
        if (z - lo > t.edge_filter_close_mm + 6 * sigma(lo) && hi - z > t.edge_filter_far_mm + 6 * sigma(hi)) ++c.flying_mid;
      } else if (e > 3) {
        const double err = z - z0;
        sum2 += err * err / (sigma(z0) * sigma(z0));
        ++n2;
      }
    }
  c.normalized_std = std::sqrt(sum2 / n2);
  std::printf("tof (driver edge filter %s): %zu edge pixels, %zu flying pixels, %zu farther than 1 px from an edge, "
              "%zu in the middle of the jump; interior: %zu of %zu missing, error / sigma = %.4f\n",
              t.driver_edge_filter ? "on" : "off", c.edge_pixels, c.flying, c.flying_far, c.flying_mid,
              c.interior_missing, c.interior, c.normalized_std);
  return c;
}

TEST(RenderNoise, TimeOfFlightFlyingPixelsOnlyAtDepthEdges) {
  // The raw time-of-flight frame: the driver's edge filter off.
  NoiseSettings raw = sensor_profile("kinect_one").noise;
  ASSERT_EQ(raw.model, "tof");
  raw.tof.driver_edge_filter = false;
  const TofCounts c = count_tof(raw);
  EXPECT_EQ(c.flying_far, 0u);
  EXPECT_GT(c.flying, c.edge_pixels / 2);  // most edge pixels fly (flying_fraction 1, a 450 mm jump)
  EXPECT_EQ(c.interior_missing, 0u);
  EXPECT_NEAR(c.normalized_std, 1.0, 0.05);
}

TEST(RenderNoise, TimeOfFlightDriverEdgeFilterDropsTheFlyingPixelsInTheMiddleOfAJump) {
  // The kinect_one profile as a user gets its frames: the driver's edge
  // filter on (its default). Of the flying pixels in the middle of the
  // 450 mm jump, few survive (their 3x3 window saw other flying pixels, not
  // both surfaces); no pixel away from the edges is lost.
  const NoiseSettings on = sensor_profile("kinect_one").noise;
  ASSERT_TRUE(on.tof.driver_edge_filter);
  NoiseSettings off = on;
  off.tof.driver_edge_filter = false;
  const TofCounts a = count_tof(off), b = count_tof(on);
  EXPECT_GT(a.flying_mid, a.edge_pixels / 4);
  EXPECT_LT(b.flying_mid, a.flying_mid / 5);
  EXPECT_LT(b.flying, a.flying / 2);
  EXPECT_EQ(b.flying_far, 0u);
  EXPECT_EQ(b.interior_missing, 0u);
  EXPECT_NEAR(b.normalized_std, 1.0, 0.05);
}

TEST(RenderNoise, GrazingAnglesHaveNoDepth) {
  // A plane tilted 70 degrees about x: along the image columns the angle
  // between ray and normal sweeps across both models' limits (80 deg).
  const Vec3 axis(1, 0, 0);
  const Mat3 R = axis_angle(axis, 70 * M_PI / 180.0);
  const Vec3 normal = R.col(2);
  for (const std::string name : {"kinect_one", "astra"}) {
    SensorProfile s = sensor_profile(name);
    if (name == "astra") {
      // The fitted astra keeps every angle (90 deg) and drops pixels along
      // edges (the plane's border): a limit to test, no edge effects.
      s.noise.structured_light.max_incidence_deg = 80;
      s.noise.structured_light.edge_dropout_rate = 0;
      s.noise.structured_light.edge_bleed_px = 0;
    }
    const double limit = name == "astra" ? s.noise.structured_light.max_incidence_deg
                                         : s.noise.tof.max_incidence_deg;
    const RenderOutput out = render_plane(s.K, 1500, 70, axis);
    const DepthImage d = noisy(out, s, s.noise, 5);
    size_t kept = 0, dropped = 0, wrong = 0;
    for (int v = 0; v < s.K.height; ++v)
      for (int u = 0; u < s.K.width; ++u) {
        const double z0 = out.depth.at(u, v);
        if (z0 <= 0 || z0 < s.min_range_mm || z0 > s.max_range_mm * 0.98) continue;
        const Vec3 ray = s.K.backproject(u, v, 1.0).normalized();
        const double incidence = std::acos(std::abs(ray.dot(normal))) * 180.0 / M_PI;
        const bool has = d.at(u, v) > 0;
        if (incidence > limit + 0.5) wrong += has, dropped += !has;
        if (incidence < limit - 0.5) wrong += !has, kept += has;
      }
    std::printf("%s: %zu pixels kept below %.0f deg incidence, %zu dropped above, %zu wrong\n", name.c_str(), kept,
                limit, dropped, wrong);
    EXPECT_EQ(wrong, 0u) << name;
    EXPECT_GT(kept, 10000u) << name;
    EXPECT_GT(dropped, 10000u) << name;
  }
}

TEST(RenderNoise, RangeLimitsDropPixels) {
  SensorProfile kin = sensor_profile("kinect_one");
  NoiseSettings none;
  const RenderOutput near = render_plane(kin.K, 300, 0);
  EXPECT_EQ(noisy(near, kin, none, 1).valid_count(), 0u);  // nearer than 500 mm
  const RenderOutput mid = render_plane(kin.K, 1000, 0);
  EXPECT_EQ(noisy(mid, kin, none, 1).z, mid.depth.z);  // no noise, in range: unchanged
}

TEST(RenderNoise, SameSeedSameImageOtherSeedDifferent) {
  for (const std::string name : {"synthetic", "astra", "kinect_one"}) {
    const SensorProfile s = sensor_profile(name);
    const RenderOutput out = render_box_wall(s.K);
    const DepthImage a = noisy(out, s, s.noise, 1234);
    const DepthImage b = noisy(out, s, s.noise, 1234);
    const DepthImage c = noisy(out, s, s.noise, 1235);
    EXPECT_EQ(a.z, b.z) << name;
    size_t differ = 0;
    for (size_t i = 0; i < a.z.size(); ++i) differ += a.z[i] != c.z[i];
    // Structured light on a fronto-parallel wall mostly rounds to the same
    // disparity level whatever the jitter, so fewer pixels change there.
    EXPECT_GT(differ, a.z.size() / 100) << name;
    EXPECT_NE(a.z, out.depth.z) << name;
  }
}

TEST(RenderNoise, NormalsEstimatedWhenNotRendered) {
  // Without rendered normals the models estimate them from the depth; the
  // estimate matches the rendered face normals on a plane.
  const SensorProfile astra = sensor_profile("astra");
  const RenderOutput out = render_plane(astra.K, 1200, 35, Vec3(1, 1, 0));
  const std::vector<Vec3f> est = estimate_normals(out.depth, astra.K);
  double worst = 0;
  for (size_t i = 0; i < est.size(); ++i)
    if (est[i].squaredNorm() > 0) worst = std::max(worst, double((est[i] - out.normals[i]).norm()));
  EXPECT_LT(worst, 1e-3);
  RenderOutput no_normals = out;
  no_normals.normals.clear();
  EXPECT_EQ(noisy(out, astra, astra.noise, 9).z, noisy(no_normals, astra, astra.noise, 9).z);
}
