// Fitting a sensor's noise model to real frames with ground truth
// (`posebench sensor-fit`). The real statistics (sensor_stats.h) are
// measured; then each candidate noise model degrades the same frames'
// renders (GT objects and the fitted supporting plane: the twin scenes) and
// the same statistics are measured on them. The candidate whose statistics
// are closest (fit_loss) is the fitted profile.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/sensor.h"
#include "simreal/sensor_stats.h"

namespace pb {

struct SensorFitSettings {
  std::string split = "test";
  SensorProfile base;           // the profile the fit starts from (its noise model is the one fitted)
  std::string name = "fitted";  // the fitted profile's name
  int max_images = 0;           // 0 = every image with depth and GT
  int stride = 1;               // every stride-th of them (video sequences: frames apart)
  uint64_t seed = 1;            // the simulated frames' noise
  SensorStatsSettings stats;
};

// The loss's parts; each is a mean over the bins with at least min_pixels
// object pixels in both sets (0 when none is).
struct FitLoss {
  double noise = 0;       // (ln spread_sim / spread_real)^2 per depth bin
  double incidence = 0;   // ((missing_sim - missing_real) / 0.1)^2 per incidence bin, geometric part
  double edge = 0;        // the same per inside distance to the outline (0..5 px)
  double silhouette = 0;  // ((object_rate_sim - object_rate_real) / 0.1)^2 for d = -2..3
  double total() const { return noise + incidence + edge + silhouette; }
};
// The missing rates compared are the geometric part: the rate r over pixels
// nothing nearer covers; for the real frames as (r - r0) / (1 - r0) with r0
// their interior frontal rate (dark or shiny surfaces: no noise model here
// produces it, see SensorStats).
FitLoss fit_loss(const SensorStats& real, const SensorStats& sim, int64_t min_pixels = 300);

struct FitCandidate {
  NoiseSettings noise;
  nlohmann::ordered_json params;  // the fitted fields' values
  FitLoss loss;
};

struct SensorFitResult {
  std::string dataset;
  int images = 0;
  Intrinsics K;                 // the first image's
  SensorStats real, base, fitted;  // measured, simulated with the base's noise, with the fit
  FitLoss base_loss;
  std::vector<FitCandidate> candidates;  // every candidate, in search order
  SensorProfile profile;        // the base with the fitted noise and the real optics
  nlohmann::ordered_json planes;  // per image: the supporting plane used
};

// InputError naming the dataset when it has no frame with depth and GT, or
// the base's noise model is not structured_light or tof.
SensorFitResult fit_sensor(const std::string& dataset, const SensorFitSettings& s);

// The fitted profile as a YAML sensor map (parse_sensor reads it).
std::string profile_yaml(const SensorProfile& p, const std::string& comment);
nlohmann::ordered_json to_json(const SensorFitResult& r);

}  // namespace pb
