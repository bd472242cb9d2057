// Sensor profiles (THESIS.md Table 2.1) and depth noise models. Every noise
// model is seeded: the same Rng state gives the same noisy image.
#pragma once

#include <string>
#include <vector>

#include "core/random.h"
#include "core/types.h"
#include "core/yaml.h"
#include "render/renderer.h"

namespace pb {

// Gaussian: z += N(0, sigma) on every valid pixel (the thesis's synthetic noise).
struct GaussianNoise {
  double sigma_mm = 1.0;  // standard deviation in mm (thesis default 1 mm)
};

// Structured light (Astra-like): depth from quantized disparity with a
// projector baseline, so the error grows with z^2; local smoothing; no depth
// in projector shadows and at grazing angles.
struct StructuredLightNoise {
  double baseline_mm = 75.0;         // projector-camera baseline along +x
  double disparity_step_px = 0.125;  // disparity quantization (subpixel step)
  double disparity_sigma_px = 0.05;  // Gaussian jitter on disparity before quantization
  int smoothing_radius_px = 1;       // box smoothing of depth over (2r+1)^2 valid neighbours
  double max_incidence_deg = 75.0;   // no depth beyond this angle between ray and normal
  bool shadows = true;               // drop pixels the projector cannot see
};

// Time of flight (Kinect-One-like): distance-dependent noise, flying pixels
// at depth edges, no depth at grazing angles.
struct TimeOfFlightNoise {
  double sigma_base_mm = 1.5;        // sigma = base + per_m2 * (z/1000)^2
  double sigma_per_m2_mm = 0.75;
  double edge_jump_mm = 30.0;        // a depth step larger than this is an edge
  double flying_fraction = 1.0;      // probability that an edge pixel becomes flying
  double max_incidence_deg = 80.0;   // no depth beyond this angle
};

struct NoiseSettings {
  std::string model = "none";  // none | gaussian | structured_light | tof
  GaussianNoise gaussian;
  StructuredLightNoise structured_light;
  TimeOfFlightNoise tof;
};

struct SensorProfile {
  std::string name;     // synthetic | astra | kinect_one | custom
  Intrinsics K;
  double depth_scale = 0.1;  // written to scene_camera.json (png * scale = mm)
  double min_range_mm = 200;
  double max_range_mm = 8000;
  NoiseSettings noise;  // the sensor's default noise model
};

// Built-in profiles: synthetic (512x512, 30x30 deg, gaussian 1 mm), astra
// (640x480, 59x46 deg, structured light), kinect_one (512x424, 57x43 deg,
// time of flight). InputError(file, field) for an unknown name.
SensorProfile sensor_profile(const std::string& name, const std::string& file = "",
                             const std::string& field = "sensor");
// A `sensor:` YAML node: either a name or a map {name, width, height, fx, fy,
// cx, cy, depth_scale, min_range_mm, max_range_mm} (custom intrinsics).
SensorProfile parse_sensor(const YamlNode& node);
// A `noise:` YAML node {model, sigma_mm, baseline_mm, ...}; fields default to
// `base`.
NoiseSettings parse_noise(const YamlNode& node, const NoiseSettings& base);

// Applies the noise model in place. `render` supplies labels and normals
// (render with RenderSettings::normals = true for the structured light and
// time of flight models); pixels outside [min, max] range become 0.
void apply_noise(DepthImage& depth, const RenderOutput& render, const SensorProfile& sensor,
                 const NoiseSettings& noise, Rng& rng);

}  // namespace pb
