// Sensor profiles (thesis Table 2.1) and depth noise models. Every noise
// model is seeded: the same Rng state gives the same noisy image.
//
// Noise models (all in mm, camera frame; `z` is the noise-free rendered depth):
// - gaussian: z += N(0, sigma_mm) on every valid pixel (the thesis's
//   synthetic images, sigma 1 mm).
// - structured_light (Astra-like): disparity d = fx * baseline / z (projector
//   at +baseline along x, rows are epipolar lines); d += N(0,
//   disparity_sigma_px); box-averaged over the (2r+1)^2 valid neighbours whose
//   true disparity is within smoothing_edge_px (the correlation window); then
//   quantized to disparity_step_px and converted back, z = fx * b / d. So the
//   error grows with z^2 / (fx b). No depth where the projector cannot see the
//   surface (shadows: another surface lies between the point and the
//   projector, found by z-buffering the points in the projector's view, which
//   is a running minimum of the projector column along each row) and where the
//   angle between the viewing ray and the normal exceeds max_incidence_deg.
// - tof (Kinect-One-like): z += N(0, sigma_base + sigma_per_m2 * (z/1000 m)^2);
//   a pixel next to (8-neighbourhood) a depth jump larger than edge_jump_mm
//   becomes, with probability flying_fraction, a flying pixel: a depth drawn
//   uniformly between the foreground and background of that jump (the mixed
//   return of a pixel straddling an edge), then the noise above. No depth
//   beyond max_incidence_deg. Then, when driver_edge_filter is on, the
//   driver's edge filter (the Kinect One's depth pipeline as libfreenect2
//   reproduces it, on by default there): a pixel whose depth lies more than
//   edge_filter_close_mm behind the nearest and more than edge_filter_far_mm
//   in front of the farthest depth of its 3x3 window, and more than
//   edge_filter_span_mm from one of them, is dropped; so the flying pixels in
//   the middle of a large jump go, those close to a surface stay.
// All models finally drop pixels outside [min_range_mm, max_range_mm].
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
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
// in projector shadows, at grazing angles and in a band along depth edges;
// the nearer surface grows over the farther.
// Defaults: fitted by `posebench sensor-fit` to real PrimeSense-class frames
// with ground truth (YCB-Video, Asus Xtion: results/sensors/real/ycbv, whose
// profile.yaml has the fit at those frames' focal length, 1066.8 px), here at
// this profile's (565.6 px): the disparity jitter, edge threshold and edge
// widths times 565.6 / 1066.8 (the same depth noise and the same widths in
// the scene). disparity_step_px keeps the steps measured on raw OpenNI
// frames (results/sensors/fit_astra.json: 2.87e-6 z^2 per mm); the
// ground-truth frames are registered to colour and interpolated and show
// none. The fit on frames without ground truth (disparity_sigma_px 0.3,
// smoothing_radius_px 2, smoothing_edge_px 1, max_incidence_deg 80, no edge
// effects) is configs/sensors/astra_no_gt.yaml (results/sim2real/README.md).
struct StructuredLightNoise {
  double baseline_mm = 75.0;         // projector-camera baseline along +x
  double disparity_step_px = 0.1216; // disparity quantization (about the 1/8 px subpixel step)
  double disparity_sigma_px = 0.69;  // Gaussian jitter on disparity before smoothing and quantization
  int smoothing_radius_px = 1;       // box smoothing of disparity over (2r+1)^2 valid neighbours
  double smoothing_edge_px = 0.13;   // neighbours whose true disparity differs more are not averaged
  double max_incidence_deg = 90.0;   // no depth beyond this angle between ray and normal
  bool shadows = true;               // drop pixels the projector cannot see
  // Depth edges, as real frames with ground truth show them. An edge is a
  // step of the true depth between 4-neighbours larger than 10 mm + 1% of
  // the nearer depth (or depth next to none).
  double edge_bleed_px = 0.27;        // the nearer surface grows over the farther by this many px (correlation window)
  double edge_dropout_rate = 0.5;    // probability of no depth at an edge pixel, falling off as
  double edge_dropout_px = 2.12;     //   exp(-d / edge_dropout_px) with the distance d (px) to the edge
  // The focal length (px) the pixel-unit fields were fitted at; at another
  // focal length the window and edge widths scale with it and the depth
  // noise stays (f x baseline is kept). 0 = the image's own.
  double reference_fx = 0;
};

// Time of flight (Kinect-One-like): distance-dependent noise, flying pixels
// at depth edges, no depth at grazing angles. Calibrated on two real Kinect v2
// frames (results/sensors/fit_kinect_one.json, results/sensors/README.md):
// the noise's level (the literature's 1.5 + 0.75 (z/1 m)^2 mm scaled by 0.55;
// the frames fix it from 0.5 to 1.25 m only), flying_fraction and
// edge_filter_span_mm (to the mixed-pixel rate at edges of the static table
// frame, which does not determine them: 0.5-1 and 100-150 mm fit it alike,
// and the search's seed decides), max_incidence_deg (unchanged by the fit).
// edge_jump_mm and the filter's two other thresholds keep their literature /
// driver values.
struct TimeOfFlightNoise {
  double sigma_base_mm = 0.825;      // sigma = base + per_m2 * (z/1000)^2 (fitted: 0.55 x the literature's 1.5)
  double sigma_per_m2_mm = 0.4125;   // growth of sigma per squared metre of depth (0.55 x 0.75)
  double edge_jump_mm = 30.0;        // a depth step larger than this is an edge
  double flying_fraction = 0.75;     // probability that an edge pixel becomes flying (fitted; literature 1)
  double max_incidence_deg = 80.0;   // no depth beyond this angle
  // The driver's edge filter. The Kinect One's driver drops most flying
  // pixels before a user sees the frame (libfreenect2, which reproduces
  // Microsoft's pipeline, has EnableEdgeAwareFilter on by default, with
  // these thresholds). Its further condition, a spread of the infrared
  // amplitude in the window of at least 5% of its mean, is taken as met: a
  // jump of 100 mm changes the amplitude (1/z^2) by 10.5% or more up to
  // about 2 m, enough for that spread when a third of the window lies
  // across the jump (the table scenes are 0.6-1.5 m away); farther away
  // this model drops more than the driver would. false = the raw
  // time-of-flight frame, every flying pixel kept.
  bool driver_edge_filter = true;
  double edge_filter_close_mm = 50.0; // drop only more than this behind the window's nearest depth
  double edge_filter_far_mm = 30.0;   // and more than this in front of its farthest depth
  double edge_filter_span_mm = 150.0; // and more than this from one of the two (fitted; libfreenect2's 100)
};

struct NoiseSettings {
  std::string model = "none";  // none | gaussian | structured_light | tof
  GaussianNoise gaussian;
  StructuredLightNoise structured_light;
  TimeOfFlightNoise tof;
};

struct SensorProfile {
  std::string name;     // synthetic | astra | kinect_one | a custom name
  Intrinsics K;
  // png * scale = mm in scene_camera.json; max_range_mm must fit a uint16
  // (max_range_mm <= 65535 * depth_scale).
  double depth_scale = 0.1;
  double min_range_mm = 200;   // nearer measurements are dropped (0)
  double max_range_mm = 6500;  // farther measurements are dropped (0)
  NoiseSettings noise;  // the sensor's default noise model
};

// Names of the built-in profiles.
std::vector<std::string> sensor_names();

// Built-in profiles: synthetic (512x512, 30x30 deg, gaussian 1 mm), astra
// (640x480, 59x46 deg, structured light), kinect_one (512x424, 57x43 deg,
// time of flight). InputError(file, field) for an unknown name.
SensorProfile sensor_profile(const std::string& name, const std::string& file = "",
                             const std::string& field = "sensor");
// A `sensor:` YAML node: either a name or a map {name, width, height, fx, fy,
// cx, cy, depth_scale, min_range_mm, max_range_mm} (custom intrinsics; instead
// of fx, fy also hfov_deg, vfov_deg; cx, cy default to the image centre). A
// map naming a built-in profile starts from it (noise model, ranges,
// depth_scale, intrinsics) and replaces what the map gives: for example
// {name: kinect_one, fx: 365, fy: 365} is the Kinect One's time-of-flight
// sensor with the real Kinect v2's optics (70.6 x 60 deg) instead of Table
// 2.1's 57 x 43 deg. A custom sensor's default noise is gaussian 1 mm.
// The map may also give `noise:` (as parse_noise reads it, starting from the
// profile's own). A scalar ending in .yaml or .yml names a profile file
// holding such a map (`posebench sensor-fit` writes one), relative to the
// YAML file that names it.
SensorProfile parse_sensor(const YamlNode& node);
// Whether a sensor name is a profile file (ends in .yaml or .yml).
bool is_profile_file(const std::string& name);
// The model's fields as a `noise:` map (parse_noise reads it back).
nlohmann::ordered_json noise_json(const NoiseSettings& n);
// The time-of-flight model's fields, in noise_json's order (noise_json's
// `tof` keys; the scene set's posebench_scene.json lists them too).
nlohmann::ordered_json tof_json(const TimeOfFlightNoise& t);
// Intrinsics from a YAML map {width, height, fx, fy | hfov_deg, vfov_deg, cx,
// cy}, each key defaulting to `base`'s (required where `base` has none; cx,
// cy to the image centre when the size differs from base's). InputError
// naming the file and the field on a bad value.
Intrinsics parse_intrinsics(const YamlNode& node, const Intrinsics& base);
// A `noise:` YAML node: a model name, or a map {model, sigma_mm (gaussian);
// baseline_mm, disparity_step_px, disparity_sigma_px, smoothing_radius_px,
// smoothing_edge_px, max_incidence_deg, shadows, edge_bleed_px,
// edge_dropout_rate, edge_dropout_px, reference_fx (structured_light);
// sigma_base_mm, sigma_per_m2_mm, edge_jump_mm, flying_fraction,
// max_incidence_deg, driver_edge_filter, edge_filter_close_mm,
// edge_filter_far_mm, edge_filter_span_mm (tof)}; fields default to `base`.
// A key of another model than the chosen one is an InputError.
NoiseSettings parse_noise(const YamlNode& node, const NoiseSettings& base);

// Applies the noise model in place. `render` supplies the normals (render with
// RenderSettings::normals = true for the structured light and time of flight
// models; without them normals are estimated from the depth); pixels outside
// [min, max] range become 0. Random draws follow the pixel order, so the
// result depends only on the input and the Rng state.
void apply_noise(DepthImage& depth, const RenderOutput& render, const SensorProfile& sensor,
                 const NoiseSettings& noise, Rng& rng);

// Pixels of `depth` that a projector at +baseline_mm along the camera's x axis
// (same orientation and intrinsics) cannot see: 1 = shadowed.
std::vector<uint8_t> projector_shadow_mask(const DepthImage& depth, const Intrinsics& K,
                                           double baseline_mm);

// Per-pixel unit normals (camera frame, facing the camera) estimated from the
// depth by central differences on the same surface; zero where undefined.
std::vector<Vec3f> estimate_normals(const DepthImage& depth, const Intrinsics& K, double edge_jump_mm = 30.0);

}  // namespace pb
