// The astra and kinect_one profiles against the statistics of real frames.
// astra: its defaults are the fit on frames with ground truth
// (results/sensors/real/ycbv/profile.yaml, checked against those frames by
// test_simreal_profiles.cpp), at the Astra's focal length; its quantization
// step and its missing data at grazing angles are checked here against the
// raw OpenNI frames without ground truth (results/sensors/fit_astra.json,
// scripts/fit_sensors.py): quantization within 15%, missing fraction on a
// plane at most the real rate + 0.10. The statistic is
// scripts/sensor_stats.py's. (The plane-patch noise of those raw frames,
// 0.7-1.1 mm below 1.5 m, is below what the frames with ground truth show on
// objects: results/sensors/README.md.) kinect_one: fit_kinect_one.json.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/rotation.h"
#include "core/yaml.h"
#include "render/sensor.h"
#include "test_render_util.h"

using namespace pb;

namespace {

nlohmann::json load_fit(const std::string& sensor) {
  const std::string path = std::string(POSEBENCH_SOURCE_DIR) + "/results/sensors/fit_" + sensor + ".json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  return nlohmann::json::parse(in);
}

// A large plane at depth z (at the image centre) turned by tilt_deg about
// `axis`, rendered and then passed through the profile's default noise.
DepthImage noisy_plane(const SensorProfile& s, double z, double tilt_deg, const Vec3& axis, uint64_t seed,
                       DepthImage* truth = nullptr) {
  DepthRenderer r(s.K, RenderSettings{50, 20000, true, true});
  const Mesh quad = pbtest::make_quad(static_cast<float>(4 * z));
  Pose T;
  T.R = axis_angle(axis.normalized(), tilt_deg * M_PI / 180.0);
  T.t = Vec3(0, 0, z);
  const RenderOutput out = r.render({{&quad, T, 1}});
  if (truth) *truth = out.depth;
  DepthImage d = out.depth;
  Rng rng(seed);
  apply_noise(d, out, s, s.noise, rng);
  return d;
}

// sensor_stats.patch_noise: (mean depth, residual RMS) of every fully valid
// 7 x 7 tile without a neighbour jump above 0.03 z + 10 mm.
std::vector<std::pair<double, double>> patch_noise(const DepthImage& d) {
  constexpr int P = 7;
  Eigen::Matrix<double, P * P, 3> A;
  for (int v = 0; v < P; ++v)
    for (int u = 0; u < P; ++u) A.row(v * P + u) << 1.0, u, v;
  const Eigen::Matrix<double, 3, P * P> pinv = (A.transpose() * A).inverse() * A.transpose();
  std::vector<std::pair<double, double>> out;
  for (int tv = 0; tv + P <= d.height; tv += P)
    for (int tu = 0; tu + P <= d.width; tu += P) {
      Eigen::Matrix<double, P * P, 1> z;
      bool ok = true;
      double jump = 0;
      for (int v = 0; v < P && ok; ++v)
        for (int u = 0; u < P && ok; ++u) {
          z(v * P + u) = d.at(tu + u, tv + v);
          ok = z(v * P + u) > 0;
          if (ok && u > 0) jump = std::max(jump, std::abs(z(v * P + u) - z(v * P + u - 1)));
          if (ok && v > 0) jump = std::max(jump, std::abs(z(v * P + u) - z((v - 1) * P + u)));
        }
      if (!ok) continue;
      const double mean = z.mean();
      if (jump > 0.03 * mean + 10.0) continue;
      const Eigen::Matrix<double, P * P, 1> resid = z - A * (pinv * z);
      out.emplace_back(mean, std::sqrt(resid.squaredNorm() / (P * P - 3)));
    }
  return out;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Per real depth bin of fit_SENSOR.json with at least min_patches real
// patches inside [z_lo, z_hi]: ln(simulated / real) of the median patch
// noise, the simulation being a plane 30 degrees from facing the camera (as
// much of a table top is) at the bin's centre with the profile's default
// noise. Prints each bin.
std::vector<double> noise_ln_ratios(const std::string& sensor, int min_patches, double z_lo, double z_hi,
                                    uint64_t seed) {
  const nlohmann::json fit = load_fit(sensor);
  EXPECT_EQ(fit["status"], "calibrated");
  const auto& bins = fit["real"]["bins_mm"];
  const auto& real = fit["real"]["noise_mm"]["median"];
  const auto& patches = fit["real"]["noise_mm"]["patches"];
  const SensorProfile profile = sensor_profile(sensor);
  std::vector<double> out;
  for (size_t i = 0; i < bins.size(); ++i) {
    const double lo = bins[i][0], hi = bins[i][1];
    if (real[i].is_null() || patches[i].get<int>() < min_patches || lo < z_lo || hi > z_hi) continue;
    const DepthImage d = noisy_plane(profile, 0.5 * (lo + hi), 30, Vec3(1, 0, 0), seed + i);
    std::vector<double> rms;
    for (const auto& [z, r] : patch_noise(d))
      if (z >= lo && z < hi) rms.push_back(r);
    EXPECT_GT(rms.size(), 100u) << sensor << " " << lo;
    if (rms.empty()) continue;
    const double sim = median(rms), ref = real[i].get<double>();
    out.push_back(std::log(sim / ref));
    std::printf("%s %4.0f-%4.0f mm: simulated %.3f mm, real %.3f mm (ln ratio %+.3f, %zu patches)\n", sensor.c_str(),
                lo, hi, sim, ref, out.back(), rms.size());
  }
  return out;
}

double mean_abs(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += std::abs(x);
  return v.empty() ? 0 : s / static_cast<double>(v.size());
}

}  // namespace

TEST(SensorCalibration, AstraQuantizationStepMatchesRealFrames) {
  const nlohmann::json fit = load_fit("astra");
  const auto& bins = fit["real"]["bins_mm"];
  const auto& real = fit["real"]["quant_step_mm"]["median"];
  const SensorProfile astra = sensor_profile("astra");
  int checked = 0;
  for (size_t i = 0; i < bins.size(); ++i) {
    const double lo = bins[i][0], hi = bins[i][1];
    if (real[i].is_null() || lo < 1500 || hi > 4000) continue;  // nearer, the real 1 mm output rounding dominates
    const DepthImage d = noisy_plane(astra, 0.5 * (lo + hi), 50, Vec3(1, 0, 0), 31 + i);
    std::vector<double> levels;
    for (float z : d.z)
      if (z >= lo && z < hi) levels.push_back(z);
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end(), [](double a, double b) { return b - a < 1e-3; }),
                 levels.end());
    ASSERT_GE(levels.size(), 5u) << lo;
    std::vector<double> gaps;
    for (size_t k = 1; k < levels.size(); ++k) gaps.push_back(levels[k] - levels[k - 1]);
    const double sim = median(gaps), ref = real[i].get<double>();
    std::printf("astra %4.0f-%4.0f mm: step simulated %.2f mm, real %.2f mm\n", lo, hi, sim, ref);
    EXPECT_NEAR(sim, ref, 0.15 * ref) << "bin " << lo << "-" << hi;
    ++checked;
  }
  EXPECT_GE(checked, 6);
}

TEST(SensorCalibration, AstraKeepsDepthWhereRealFramesDoAtGrazingAngles) {
  // A plane tilted about x seen at 1200 mm: each pixel's incidence angle is
  // known from the rendered geometry. Per real angle bin below the fitted
  // max_incidence_deg, the simulated missing fraction of the plane's pixels
  // must not exceed the real one (planar 8 x 8 blocks) by more than 0.10.
  const nlohmann::json fit = load_fit("astra");
  const auto& edges = fit["real"]["incidence"]["bins_deg"];
  const auto& real = fit["real"]["incidence"]["missing_rate"];
  const double max_inc = fit["fitted_noise"]["max_incidence_deg"];
  const SensorProfile astra = sensor_profile("astra");
  std::vector<double> miss(real.size(), 0), total(real.size(), 0);
  for (double tilt : {20.0, 50.0, 70.0}) {
    DepthImage truth;
    const Vec3 axis(1, 0, 0);
    const DepthImage d = noisy_plane(astra, 1200, tilt, axis, 53, &truth);
    const Vec3 normal = axis_angle(axis, tilt * M_PI / 180.0).col(2);
    for (int v = 0; v < truth.height; ++v)
      for (int u = 0; u < truth.width; ++u) {
        const double z0 = truth.at(u, v);
        if (z0 < astra.min_range_mm || z0 > astra.max_range_mm) continue;
        const double inc = std::acos(std::abs(astra.K.backproject(u, v, 1.0).normalized().dot(normal))) * 180 / M_PI;
        for (size_t b = 0; b < real.size(); ++b)
          if (inc >= edges[b].get<double>() && inc < edges[b + 1].get<double>()) {
            miss[b] += d.at(u, v) <= 0;
            total[b] += 1;
          }
      }
  }
  int checked = 0;
  for (size_t b = 0; b < real.size(); ++b) {
    const double a0 = edges[b], a1 = edges[b + 1];
    if (real[b].is_null() || total[b] < 1000 || 0.5 * (a0 + a1) >= max_inc) continue;
    const double sim = miss[b] / total[b], ref = real[b].get<double>();
    std::printf("astra incidence %2.0f-%2.0f deg: simulated missing %.3f (%.0f px), real %.3f\n", a0, a1, sim,
                total[b], ref);
    EXPECT_LE(sim, ref + 0.10) << a0 << "-" << a1 << " deg";
    ++checked;
  }
  EXPECT_GE(checked, 5);
}

TEST(SensorCalibration, AstraProfileDefaultsAreTheCommittedFit) {
  // The fit on frames with ground truth (results/sensors/real/ycbv, at its
  // frames' focal length), at the Astra's focal length: disparity jitter,
  // edge threshold and widths times fx_astra / fx_fit (sensor.h); the
  // quantization step from the raw frames without ground truth.
  const SensorProfile fit = parse_sensor(
      YamlNode::load_file(std::string(POSEBENCH_SOURCE_DIR) + "/results/sensors/real/ycbv/profile.yaml"));
  const StructuredLightNoise& f = fit.noise.structured_light;
  const SensorProfile astra = sensor_profile("astra");
  const StructuredLightNoise& s = astra.noise.structured_light;
  ASSERT_GT(f.reference_fx, 0);
  const double k = astra.K.fx / f.reference_fx;
  EXPECT_NEAR(s.disparity_sigma_px, f.disparity_sigma_px * k, 0.01);
  EXPECT_NEAR(s.smoothing_edge_px, f.smoothing_edge_px * k, 0.01);
  EXPECT_EQ(s.smoothing_radius_px, static_cast<int>(std::lround(f.smoothing_radius_px * k)));
  EXPECT_NEAR(s.edge_bleed_px, f.edge_bleed_px * k, 0.01);
  EXPECT_NEAR(s.edge_dropout_px, f.edge_dropout_px * k, 0.01);
  EXPECT_DOUBLE_EQ(s.edge_dropout_rate, f.edge_dropout_rate);
  EXPECT_DOUBLE_EQ(s.max_incidence_deg, f.max_incidence_deg);
  EXPECT_DOUBLE_EQ(s.baseline_mm, f.baseline_mm);
  EXPECT_EQ(s.reference_fx, 0);  // the Astra's own focal length
  EXPECT_DOUBLE_EQ(s.disparity_step_px, load_fit("astra")["fitted_noise"]["disparity_step_px"].get<double>());
}

TEST(SensorCalibration, KinectOneProfileDefaultsAreTheCommittedFit) {
  const nlohmann::json fit = load_fit("kinect_one");
  ASSERT_EQ(fit["status"], "calibrated");
  ASSERT_FALSE(fit["sources"].empty());
  const nlohmann::json f = fit["fitted_noise"];
  const TimeOfFlightNoise& t = sensor_profile("kinect_one").noise.tof;
  EXPECT_DOUBLE_EQ(t.sigma_base_mm, f["sigma_base_mm"].get<double>());
  EXPECT_DOUBLE_EQ(t.sigma_per_m2_mm, f["sigma_per_m2_mm"].get<double>());
  EXPECT_DOUBLE_EQ(t.edge_jump_mm, f["edge_jump_mm"].get<double>());
  EXPECT_DOUBLE_EQ(t.flying_fraction, f["flying_fraction"].get<double>());
  EXPECT_DOUBLE_EQ(t.max_incidence_deg, f["max_incidence_deg"].get<double>());
  EXPECT_EQ(t.driver_edge_filter, f["driver_edge_filter"].get<bool>());
  EXPECT_DOUBLE_EQ(t.edge_filter_close_mm, f["edge_filter_close_mm"].get<double>());
  EXPECT_DOUBLE_EQ(t.edge_filter_far_mm, f["edge_filter_far_mm"].get<double>());
  EXPECT_DOUBLE_EQ(t.edge_filter_span_mm, f["edge_filter_span_mm"].get<double>());
}

TEST(SensorCalibration, KinectOneNoisePerDistanceMatchesRealFrames) {
  // The bins the fit used (at least 200 real patches: 0.5-1.25 m); a plane
  // 30 degrees from facing the camera. Tolerances: per bin |ln(simulated /
  // real)| <= 0.35, mean over the bins <= 0.2. The real noise is flat over
  // these bins (1.32, 1.14, 1.12 mm), the model's grows with z^2 (its shape
  // is the literature's, only its level fitted), and the 0.5-0.75 m bin's
  // patches lie on a forearm, whose curvature adds to a plane fit's
  // residual: the fitted model is 0.30 below it in ln ratio, 0.17 above at
  // 1-1.25 m. The literature's defaults (1.5 + 0.75 z^2 mm) fail: 1.8-2.4
  // mm on these planes (ln ratio +0.29, +0.58, +0.77, mean 0.55).
  const std::vector<double> lr = noise_ln_ratios("kinect_one", 200, 0, 1e9, 71);
  for (double x : lr) EXPECT_LE(std::abs(x), 0.35);
  ASSERT_GE(lr.size(), 3u);
  EXPECT_LE(mean_abs(lr), 0.2);
}
