// Sensor profiles and their YAML: built-in values (thesis Table 2.1),
// custom intrinsics, noise settings, and bad input naming file and field.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "core/error.h"
#include "render/sensor.h"

using namespace pb;

namespace {

// Field of view covered edge to edge by `pixels` at focal length f.
double fov_deg(int pixels, double f) { return 2.0 * std::atan(0.5 * pixels / f) * 180.0 / M_PI; }

// Runs `fn` and returns the InputError it throws (fails the test otherwise).
template <typename Fn>
InputError input_error(Fn fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError thrown";
  return InputError("", "", "");
}

SensorProfile sensor_from(const std::string& yaml, const std::string& file = "scene.yaml") {
  return parse_sensor(YamlNode::load_string(yaml, file)["sensor"]);
}

NoiseSettings noise_from(const std::string& yaml, const NoiseSettings& base = {}) {
  return parse_noise(YamlNode::load_string(yaml, "cfg.yaml")["noise"], base);
}

}  // namespace

TEST(RenderSensorYaml, BuiltInProfilesFollowTable21) {
  struct Row {
    const char* name;
    int w, h;
    double hfov, vfov;
    const char* noise;
  };
  for (const Row& r : {Row{"synthetic", 512, 512, 30, 30, "gaussian"}, Row{"astra", 640, 480, 59, 46, "structured_light"},
                       Row{"kinect_one", 512, 424, 57, 43, "tof"}}) {
    const SensorProfile s = sensor_profile(r.name);
    EXPECT_EQ(s.K.width, r.w);
    EXPECT_EQ(s.K.height, r.h);
    EXPECT_NEAR(fov_deg(r.w, s.K.fx), r.hfov, 1e-9);
    EXPECT_NEAR(fov_deg(r.h, s.K.fy), r.vfov, 1e-9);
    EXPECT_DOUBLE_EQ(s.K.cx, 0.5 * (r.w - 1));
    EXPECT_DOUBLE_EQ(s.K.cy, 0.5 * (r.h - 1));
    EXPECT_EQ(s.noise.model, r.noise);
    EXPECT_LE(s.max_range_mm, 65535 * s.depth_scale);  // fits a uint16 PNG
    EXPECT_LT(s.min_range_mm, s.max_range_mm);
    // Same through YAML, by name.
    const SensorProfile y = sensor_from(std::string("sensor: ") + r.name);
    EXPECT_EQ(y.name, r.name);
    EXPECT_EQ(y.K.fx, s.K.fx);
  }
  EXPECT_DOUBLE_EQ(sensor_profile("synthetic").noise.gaussian.sigma_mm, 1.0);  // the thesis's 1 mm
}

TEST(RenderSensorYaml, CustomIntrinsicsAndOverrides) {
  const SensorProfile s = sensor_from(
      "sensor:\n  name: my_cam\n  width: 320\n  height: 240\n  fx: 300.5\n  fy: 301\n  cx: 160.2\n  cy: 118\n"
      "  depth_scale: 0.25\n  max_range_mm: 9000\n");
  EXPECT_EQ(s.name, "my_cam");
  EXPECT_EQ(s.K.width, 320);
  EXPECT_EQ(s.K.height, 240);
  EXPECT_DOUBLE_EQ(s.K.fx, 300.5);
  EXPECT_DOUBLE_EQ(s.K.fy, 301);
  EXPECT_DOUBLE_EQ(s.K.cx, 160.2);
  EXPECT_DOUBLE_EQ(s.K.cy, 118);
  EXPECT_DOUBLE_EQ(s.depth_scale, 0.25);
  EXPECT_DOUBLE_EQ(s.max_range_mm, 9000);
  EXPECT_EQ(s.noise.model, "gaussian");

  const SensorProfile f = sensor_from("sensor: {width: 200, height: 100, hfov_deg: 60, vfov_deg: 33}");
  EXPECT_NEAR(fov_deg(200, f.K.fx), 60, 1e-9);
  EXPECT_DOUBLE_EQ(f.K.cx, 99.5);

  const SensorProfile o = sensor_from("sensor: {name: kinect_one, max_range_mm: 4000}");
  EXPECT_EQ(o.K.width, 512);
  EXPECT_DOUBLE_EQ(o.max_range_mm, 4000);
}

TEST(RenderSensorYaml, NoiseSettingsParse) {
  NoiseSettings n = noise_from("noise: {model: gaussian, sigma_mm: 2.5}");
  EXPECT_EQ(n.model, "gaussian");
  EXPECT_DOUBLE_EQ(n.gaussian.sigma_mm, 2.5);
  n = noise_from("noise: none", sensor_profile("astra").noise);
  EXPECT_EQ(n.model, "none");
  n = noise_from("noise: {baseline_mm: 50, smoothing_radius_px: 2, shadows: false, max_incidence_deg: 70}",
                 sensor_profile("astra").noise);
  EXPECT_EQ(n.model, "structured_light");
  EXPECT_DOUBLE_EQ(n.structured_light.baseline_mm, 50);
  EXPECT_EQ(n.structured_light.smoothing_radius_px, 2);
  EXPECT_FALSE(n.structured_light.shadows);
  EXPECT_DOUBLE_EQ(n.structured_light.max_incidence_deg, 70);
  n = noise_from("noise: {model: tof, sigma_base_mm: 1, flying_fraction: 0.5}");
  EXPECT_DOUBLE_EQ(n.tof.sigma_base_mm, 1);
  EXPECT_DOUBLE_EQ(n.tof.flying_fraction, 0.5);
  EXPECT_DOUBLE_EQ(n.tof.sigma_per_m2_mm, TimeOfFlightNoise{}.sigma_per_m2_mm);
  EXPECT_TRUE(n.tof.driver_edge_filter);
  n = noise_from("noise: {model: tof, driver_edge_filter: false, edge_filter_close_mm: 40, edge_filter_far_mm: 20, edge_filter_span_mm: 80}");
  EXPECT_FALSE(n.tof.driver_edge_filter);
  EXPECT_DOUBLE_EQ(n.tof.edge_filter_close_mm, 40);
  EXPECT_DOUBLE_EQ(n.tof.edge_filter_far_mm, 20);
  EXPECT_DOUBLE_EQ(n.tof.edge_filter_span_mm, 80);
  // Absent: the base.
  n = noise_from("other: 1", sensor_profile("kinect_one").noise);
  EXPECT_EQ(n.model, "tof");
}

TEST(RenderSensorYaml, UnknownSensorNameNamesFileAndField) {
  // From a real file, as the generator reads it.
  const std::string file = ::testing::TempDir() + "/posebench_bad_sensor.yaml";
  {
    std::ofstream out(file);
    out << "scenario: table\nsensor: kinect_two\nseed: 1\n";
  }
  const InputError e = input_error([&] { parse_sensor(YamlNode::load_file(file)["sensor"]); });
  const std::string msg = e.what();
  std::printf("message: %s\n", msg.c_str());
  EXPECT_EQ(e.file(), file);
  EXPECT_EQ(e.field(), "sensor");
  EXPECT_NE(msg.find(file), std::string::npos);
  EXPECT_NE(msg.find("sensor"), std::string::npos);
  EXPECT_NE(msg.find("kinect_two"), std::string::npos);
  std::remove(file.c_str());

  const InputError m = input_error([] { sensor_from("sensor: {name: astro}", "a.yaml"); });
  EXPECT_EQ(m.file(), "a.yaml");
  EXPECT_EQ(m.field(), "sensor.name");
}

TEST(RenderSensorYaml, BadValuesNameTheirField) {
  struct Case {
    std::string yaml, field;
    bool noise;
  };
  const std::vector<Case> cases = {
      {"noise: {model: gaussian, sigma_mm: -1}", "noise.sigma_mm", true},
      {"noise: {model: perlin}", "noise.model", true},
      {"noise: kinect", "noise", true},
      {"noise: {model: gaussian, baseline_mm: 10}", "noise.baseline_mm", true},
      {"noise: {model: gaussian, sigmaa: 1}", "noise.sigmaa", true},
      {"noise: {model: tof, flying_fraction: 1.5}", "noise.flying_fraction", true},
      {"noise: {model: tof, max_incidence_deg: 120}", "noise.max_incidence_deg", true},
      {"noise: {model: structured_light, disparity_step_px: 0}", "noise.disparity_step_px", true},
      {"noise: {model: structured_light, smoothing_radius_px: -2}", "noise.smoothing_radius_px", true},
      {"noise: {model: gaussian, sigma_mm: abc}", "noise.sigma_mm", true},
      {"sensor: {width: 320, height: 240, fx: -5, fy: 300}", "sensor.fx", false},
      {"sensor: {width: 0, height: 240, fx: 5, fy: 300}", "sensor.width", false},
      {"sensor: {width: 320, height: 240, fx: 300}", "sensor.fy", false},
      {"sensor: {width: 320, height: 240, hfov_deg: 200, vfov_deg: 40}", "sensor.hfov_deg", false},
      {"sensor: {name: astra, depth_scale: -0.1}", "sensor.depth_scale", false},
      {"sensor: {name: astra, min_range_mm: 900, max_range_mm: 800}", "sensor.max_range_mm", false},
      {"sensor: {name: synthetic, depth_scale: 0.1}", "sensor.depth_scale", false},
      {"sensor: {name: astra, focal: 3}", "sensor.focal", false},
  };
  for (const Case& c : cases) {
    const InputError e = input_error([&] {
      if (c.noise) noise_from(c.yaml);
      else sensor_from(c.yaml, "cfg.yaml");
    });
    EXPECT_EQ(e.field(), c.field) << c.yaml << " -> " << e.what();
    EXPECT_FALSE(e.file().empty()) << c.yaml;
    EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
  }
}
