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
//
// Layout details (optional, rarely changed; the defaults are the values the
// generator always used, see the field comments below):
//   camera: {near_mm, far_mm, clearance_mm, depth_clearance_mm}
//   distractors: {placement_tries, spread_min_radii, image_margin}
//   occlusion: {box_probability, box_width, box_depth_mm, cylinder_radius,
//               cylinder_min_radius_mm, lateral_offset, extra_distance,
//               height_factor, height_margin_mm, camera_headroom_mm,
//               min_height_mm, token_height, search_iterations,
//               search_tolerance, footprint_sides, cylinder_segments}
//   warehouse: {wall_yaw_deg, wall_thickness_mm, wall_length_mm,
//               floor_size_mm, floor_thickness_mm}
// posebench_scene.json lists a layout detail only when it differs from its
// default (so scene sets made with the defaults keep their bytes).
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
  // Clipping planes of the depth renderer (mm, along the optical axis).
  double near_mm = 50;
  double far_mm = 40000;
  // Placement clearance: an object's (or occluder's) bounding sphere must stay
  // this far (mm) beyond near_mm from the camera centre ...
  double clearance_mm = 50;
  // ... and its nearest point this far (mm) beyond near_mm in camera depth.
  double depth_clearance_mm = 20;
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
  // Random positions tried per object before the layout is given up.
  int placement_tries = 60;
  // Objects are scattered over a disc around the target as wide as the view
  // at the target's distance, but at least this many target footprint radii.
  double spread_min_radii = 3.0;
  // An object's origin must project inside the image enlarged by this
  // fraction of its width / height on each side.
  double image_margin = 0.05;
};

struct OcclusionSettings {
  bool enabled = false;  // false: "none", no occluder is placed
  // Share of the images that get an occluder between camera and target.
  double probability = 1.0;
  // The occluder's size is searched so that the target's visible fraction
  // lands in this range (drawn uniformly per image).
  ValueRange visib_fract{0.4, 0.9};
  // Shape and place of the occluder. r_t below is the target's footprint
  // radius (largest distance of its footprint from its origin, mm).
  double box_probability = 0.65;     // a box; otherwise an upright cylinder
  ValueRange box_width{0.8, 1.6};    // box width (across the view), in units of 2 r_t
  // Box depth (along the view), mm. table: 30-80, warehouse: 300-800.
  ValueRange box_depth_mm{30, 80};
  ValueRange cylinder_radius{0.5, 1.0};  // cylinder radius, in units of r_t ...
  // ... but at least this (mm). table: 20, warehouse: 150.
  double cylinder_min_radius_mm = 20;
  // Sideways offset of its centre from the camera-target line, in units of r_t.
  ValueRange lateral_offset{-0.5, 0.5};
  // Distance added to the closest position (footprints gap_mm apart), in units of r_t.
  ValueRange extra_distance{0.0, 0.5};
  // Tallest occluder tried: height_factor * (height hiding the whole target)
  // + height_margin_mm, but at least camera_headroom_mm below the camera;
  // below min_height_mm the layout is resampled (mm).
  double height_factor = 1.3;
  double height_margin_mm = 20;
  double camera_headroom_mm = 100;
  double min_height_mm = 5;
  // Height search (regula falsi on the target's visible fraction): when the
  // target is already occluded enough without it, a token occluder of this
  // fraction of the tallest height; at most search_iterations steps, stopping
  // once the visible fraction is within search_tolerance of the goal.
  double token_height = 0.02;
  int search_iterations = 12;
  double search_tolerance = 0.02;
  int footprint_sides = 24;    // polygon approximating a cylinder's footprint (overlap tests)
  int cylinder_segments = 32;  // segments of the rendered cylinder mesh
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
  // The wall is turned by up to this angle (deg, either way) from facing the
  // camera's ground direction.
  double wall_yaw_deg = 15;
  double wall_thickness_mm = 200;
  double wall_length_mm = 30000;
  double floor_size_mm = 40000;     // edge of the square floor slab
  double floor_thickness_mm = 100;  // its top is the ground plane z = 0
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
