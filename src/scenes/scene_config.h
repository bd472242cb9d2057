// Scene set configuration (configs/scenes/*.yaml): one struct mirrored one to
// one by the YAML file. Defaults follow the thesis (30 images, Gaussian noise
// of 1 mm for the synthetic sensor, LS5 as the target) and issue 2 (table:
// camera 0.6-1.5 m away looking down 30-70 deg, 3-8 distractors;
// warehouse: camera 2-5 m away, 1-3 objects of 1-1.5 m, a wall behind).
//
// YAML (every key optional except scenario):
//   scenario: table                 # table | warehouse
//   description: "free text"
//   scene_id: 1                     # BOP scene folder test/000001
//   seed: 1                         # every random choice derives from it
//   images: 30
//   sensor: astra                   # synthetic | astra | kinect_one | {name: custom, width: ...}
//   noise: {model: gaussian, sigma_mm: 1.0}   # default: the sensor's model
//   depth_scale: 0.1                # png value * depth_scale = mm; default: the sensor's
//   registry: ../../models/models.yaml        # relative to this file; default: the tree's
//   target: ls5
//   target_upright_probability: 0.5
//   min_target_visib: 0.5
//   distractors: {pool: [milk_carton, boletus], count: [3, 8], upright_probability: 0.5}
//   occlusion: none                 # none | [0.4, 0.9] | {visib_fract: [0.4, 0.9], probability: 1.0}
//   camera: {distance_mm: [600, 1500], elevation_deg: [30, 70], look_jitter: 0.15}
//   table: {size_mm: 4000, thickness_mm: 40}
//   warehouse: {object_size_mm: [1000, 1500], wall_distance_mm: [800, 2000], wall_height_mm: 5000}
//   masks: true
//   max_attempts: 200
// A scalar where a range is expected means a fixed value.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/yaml.h"
#include "render/sensor.h"

namespace pb {

// A closed interval sampled uniformly; lo == hi is a fixed value.
struct ValueRange {
  double lo = 0;
  double hi = 0;
};

enum class Scenario { table, warehouse };
std::string scenario_name(Scenario s);

struct SceneCameraSettings {
  // Distance from the camera to the point it looks at (the target's centre
  // plus jitter). table: 600-1500 mm, warehouse: 2000-5000 mm.
  ValueRange distance_mm{600, 1500};
  // Angle of the optical axis below the horizontal. table: 30-70 deg,
  // warehouse: 5-30 deg.
  ValueRange elevation_deg{30, 70};
  // The look-at point is shifted in the image plane by up to this fraction of
  // the half field of view at that distance, so the target is not always at
  // the image centre.
  double look_jitter = 0.15;
};

struct DistractorSettings {
  // Registry names the other objects are drawn from (with replacement; the
  // target's name is skipped). Procedural models need no ../shared.
  // table: milk_carton, boletus, box_small, cylinder; warehouse: pallet,
  // box_large, barrel.
  std::vector<std::string> pool;
  // Number of other objects per image (inclusive). table: 3-8, warehouse: 0-2
  // (so 1 to 3 objects in all).
  int min_count = 3;
  int max_count = 8;
  // Probability that an object stands upright; otherwise a rest pose is drawn
  // by its quasi-static probability (lying on a side, tipped over...).
  double upright_probability = 0.5;
};

struct OcclusionSettings {
  bool enabled = false;  // false: "none", no occluder is placed
  // Share of the images that get an occluder between camera and target.
  double probability = 1.0;
  // The occluder's size is searched so that the target's visible fraction
  // lands in this range (drawn uniformly per image).
  ValueRange visib_fract{0.4, 0.9};
};

struct TableSettings {
  double size_mm = 4000;      // edge of the square table top (a plane in practice)
  double thickness_mm = 40;   // table top thickness
  double gap_mm = 10;         // minimum distance between object footprints
};

struct WarehouseSettings {
  // Every model's largest extent is scaled to a size drawn once per data set
  // from this range (the same mesh in every image, as BOP requires).
  ValueRange object_size_mm{1000, 1500};
  // Distance from the target to the wall behind it (seen from the camera).
  ValueRange wall_distance_mm{800, 2000};
  double wall_height_mm = 5000;
  double gap_mm = 100;        // minimum distance between object footprints
};

struct SceneSettings {
  std::string name;           // scene set name (the config file's stem)
  std::string config_file;    // the file it was read from ("" if built in code)
  std::string description;    // free text, copied to posebench_scene.json
  Scenario scenario = Scenario::table;
  int scene_id = 1;           // BOP scene id: DIR/test/000001
  uint64_t seed = 1;          // base seed of every random choice
  int images = 30;            // images in the scene (the thesis: 30)
  std::string sensor_name = "synthetic";
  SensorProfile sensor;       // resolved profile (intrinsics, range)
  NoiseSettings noise;        // noise applied to the rendered depth (default: the sensor's)
  double depth_scale = 0.1;   // png * depth_scale = mm (default: the sensor's)
  std::string registry;       // model registry file, "" = the default registry
  std::string target = "ls5"; // registry name of the object of interest
  // Probability that the target stands upright (the thesis's real scenes: 1).
  double target_upright_probability = 0.5;
  // Without an occluder, the target's visible fraction must reach this
  // (otherwise the layout is resampled).
  double min_target_visib = 0.5;
  DistractorSettings distractors;
  OcclusionSettings occlusion;
  SceneCameraSettings camera;
  TableSettings table;
  WarehouseSettings warehouse;
  bool masks = true;          // also write mask_visib/IIIIII_GGGGGG.png
  int max_attempts = 200;     // layouts tried per image before giving up
};

// Defaults of a scenario (camera ranges, distractor counts).
SceneSettings default_scene_settings(Scenario s);

// Parses a scene config. InputError naming file and field (with line) on
// unknown keys, wrong types, negative sizes, bad ranges, unknown scenario
// or sensor.
SceneSettings parse_scene_settings(const YamlNode& root);
SceneSettings load_scene_settings(const std::string& path);

// The resolved settings as JSON text (posebench_scene.json, traceability).
std::string scene_settings_json(const SceneSettings& s);

}  // namespace pb
