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
//   stated_intrinsics: {hfov_deg: 57, vfov_deg: 43}   # what the files state; default: the sensor's
//   registry: ../../models/models.yaml        # relative to this file; default: the tree's
//   target: ls5
//   target_upright_probability: 0.5
//   target_free_probability: 0       # else a uniformly random orientation on its lowest point
//   target_tilt_deg: 0               # rest pose leaned by up to this many degrees
//   min_target_visib: 0.5
//   distractors: {pool: [milk_carton, boletus], count: [3, 8], upright_probability: 0.5}
//   occlusion: none                 # none | [0.4, 0.9] | {visib_fract: [0.4, 0.9], probability: 1.0}
//   camera: {distance_mm: [600, 1500], elevation_deg: [30, 70], look_jitter: 0.15}
//   table: {size_mm: 4000, thickness_mm: 40}
//   warehouse: {object_size_mm: [1000, 1500], wall_distance_mm: [800, 2000], wall_height_mm: 5000}
//   setups: 0                       # > 0: that many object layouts, the camera drawn per image
//   masks: true
//   max_attempts: 200
// A scalar where a range is expected means a fixed value.
//
// Layout details (optional, rarely changed; the defaults are the values the
// generator always used, see the field comments below):
//   camera: {near_mm, far_mm, clearance_mm, depth_clearance_mm}
//   distractors: {placement_tries, spread_min_radii, spread_max_radii, image_margin}
//   occlusion: {box_probability, box_width, box_depth_mm, cylinder_radius,
//               cylinder_min_radius_mm, lateral_offset, extra_distance,
//               height_factor, height_margin_mm, camera_headroom_mm,
//               min_height_mm, token_height, search_iterations,
//               search_tolerance, footprint_sides, cylinder_segments}
//   warehouse: {wall_yaw_deg, wall_thickness_mm, wall_length_mm,
//               floor_size_mm, floor_thickness_mm}
//   table: {floor_drop_mm, wall_distance_mm}   # a room around the table
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
  // Layout details. Clearances are mm beyond near_mm: an object's (or the
  // occluder's) bounding sphere must keep them from the camera.
  double near_mm = 50;              // near clipping plane of the renderer, mm
  double far_mm = 40000;            // far clipping plane of the renderer, mm
  double clearance_mm = 50;         // sphere to camera centre (3D distance), mm
  double depth_clearance_mm = 20;   // sphere's nearest point in camera depth z, mm
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
  // Layout details. The scatter disc around the target is as wide as the
  // view at the target's distance, but at least spread_min_radii target
  // footprint radii (and at most spread_max_radii, when that is not 0: the
  // other objects crowded around the target); an object's origin must
  // project inside the image enlarged by image_margin (fraction of its
  // width / height) on each side.
  int placement_tries = 60;         // random positions tried per object before the layout is given up
  double spread_min_radii = 3.0;    // minimum scatter disc radius, in target footprint radii
  double spread_max_radii = 0.0;    // maximum one, in target footprint radii; 0: none (as wide as the view)
  double image_margin = 0.05;       // fraction of the image size, each side
};

struct OcclusionSettings {
  bool enabled = false;  // false: "none", no occluder is placed
  // Share of the images that get an occluder between camera and target.
  double probability = 1.0;
  // The occluder's size is searched so that the target's visible fraction
  // lands in this range (drawn uniformly per image).
  ValueRange visib_fract{0.4, 0.9};
  // Layout details: shape and place of the occluder. r_t is the target's
  // footprint radius (largest distance of its footprint from its origin).
  // Its tallest height tried is height_factor * (the height hiding the whole
  // target) + height_margin_mm, at least camera_headroom_mm below the camera;
  // below min_height_mm the layout is resampled. The height is searched by
  // regula falsi on the target's visible fraction (at most search_iterations
  // steps, stopping within search_tolerance of the goal); a target occluded
  // enough without it gets a token occluder of token_height * the tallest.
  double box_probability = 0.65;          // a box, otherwise an upright cylinder
  ValueRange box_width{0.8, 1.6};         // across the view, in units of 2 r_t
  ValueRange box_depth_mm{30, 80};        // along the view, mm (warehouse: 300-800)
  ValueRange cylinder_radius{0.5, 1.0};   // in units of r_t, but at least:
  double cylinder_min_radius_mm = 20;     // mm (warehouse: 150)
  ValueRange lateral_offset{-0.5, 0.5};   // centre's offset across the camera-target line, units of r_t
  ValueRange extra_distance{0.0, 0.5};    // added to the closest position (gap_mm apart), units of r_t
  double height_factor = 1.3;             // times the height hiding the target (unitless)
  double height_margin_mm = 20;           // added to that height, mm
  double camera_headroom_mm = 100;        // tallest height stays this far below the camera, mm
  double min_height_mm = 5;               // a smaller tallest height: no room, resample, mm
  double token_height = 0.02;             // token occluder, fraction of the tallest height
  int search_iterations = 12;             // regula falsi steps at most
  double search_tolerance = 0.02;         // stop when |visible fraction - goal| is at most this
  int footprint_sides = 24;               // polygon of a cylinder's footprint (overlap tests)
  int cylinder_segments = 32;             // segments of the rendered cylinder mesh
};

struct TableSettings {
  double size_mm = 4000;      // edge of the square table top (a plane in practice)
  double thickness_mm = 40;   // table top thickness
  double gap_mm = 10;         // minimum distance between object footprints
  // A room around the table (layout details; by default none: the table
  // top fills the view and nothing else is in range). The floor slab and
  // the wall are the warehouse's (warehouse.floor_* and wall_* details).
  double floor_drop_mm = 0;            // > 0: a floor this far below the table top, mm
  ValueRange wall_distance_mm{0, 0};   // > 0: a wall behind the table as seen from the camera,
                                       // this far beyond the table's farthest corner (drawn
                                       // per image), from the floor (or the table top) up, mm
};

struct WarehouseSettings {
  // Every model's largest extent is scaled to a size drawn once per data set
  // from this range (the same mesh in every image, as BOP requires).
  ValueRange object_size_mm{1000, 1500};
  // Distance from the target to the wall behind it (seen from the camera).
  ValueRange wall_distance_mm{800, 2000};
  double wall_height_mm = 5000;
  double gap_mm = 100;        // minimum distance between object footprints
  // Layout details of the background.
  double wall_yaw_deg = 15;         // wall turned by up to this from facing the camera, deg (either way)
  double wall_thickness_mm = 200;   // wall thickness, mm
  double wall_length_mm = 30000;    // wall length, mm
  double floor_size_mm = 40000;     // edge of the square floor slab, mm
  double floor_thickness_mm = 100;  // floor slab thickness (its top is z = 0), mm
  // A wall behind the target as well as the floor. false: the floor alone,
  // one dominant plane, as the thesis's warehouse scenes ("a plane was added
  // behind the objects to simulate a floor or a wall").
  bool wall = true;
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
  // Intrinsics the data set states (camera.json, scene_camera.json) where
  // they differ from the optics that rendered it (`sensor`): frames that a
  // program back-projects with a data sheet's field of view instead of the
  // sensor's own. A true camera-frame point p then reads as K_stated^-1 K p
  // (its depth kept), so the ground truth's translation is mapped so and its
  // rotation kept: the pose whose model overlays the object in the image, as
  // a visual check accepts it. Same image size as the sensor's. Off
  // (default): the sensor's intrinsics.
  bool has_stated_intrinsics = false;
  Intrinsics stated_intrinsics;
  std::string registry;       // model registry file, "" = the default registry
  std::string target = "ls5"; // registry name of the object of interest
  // Probability that the target stands upright (the thesis's real scenes: 1).
  double target_upright_probability = 0.5;
  // Probability that the target is placed in a uniformly random orientation
  // instead of a rest pose (resting on its lowest point, yawed at random; not
  // physically stable): the thesis's synthetic table shows its statue
  // "upside down" (section 4.1.2). 0 (default): rest poses only, and no
  // random draw is spent on it, so existing scene sets stay the same.
  double target_free_probability = 0.0;
  // The target, in its rest pose, leaned by a uniform angle of up to this
  // many degrees about a random horizontal axis, resting on its lowest point
  // (not physically stable): the thesis's synthetic LS5 is "slightly tilted"
  // (section 4.1.2) and "not standing upright" (Table 4.4's text). 0
  // (default): no lean, and no random draw is spent on it.
  double target_tilt_deg = 0.0;
  // Without an occluder, the target's visible fraction must reach this
  // (otherwise the layout is resampled).
  double min_target_visib = 0.5;
  DistractorSettings distractors;
  OcclusionSettings occlusion;
  SceneCameraSettings camera;
  TableSettings table;
  WarehouseSettings warehouse;
  // > 0: the images show this many set-ups, image i set-up i mod setups. A
  // set-up is one layout of the target and the other objects, drawn once
  // from its own stream (and accepted from a reference camera as an image
  // would be); each image then draws only its camera (camera.*) around it,
  // keeping the objects where they stand: a few arrangements photographed
  // many times, as the thesis's real frames show "the setup" of its Figure
  // 4.3, so images of one set-up are not independent. 0 (default): a new
  // layout per image. Not with occlusion or a wall (they are placed for
  // one camera: on its line of sight, behind the target).
  int setups = 0;
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

// The intrinsics the data set's files state: stated_intrinsics when set,
// else the sensor's.
const Intrinsics& dataset_intrinsics(const SceneSettings& s);

// A ground-truth pose as a data set with stated intrinsics `stated` reads it
// when the optics were K: the translation mapped by stated^-1 K, the
// rotation kept (see SceneSettings::stated_intrinsics).
Pose stated_pose(const Pose& T_cam_model, const Intrinsics& K, const Intrinsics& stated);

// The resolved settings as JSON text (posebench_scene.json, traceability).
std::string scene_settings_json(const SceneSettings& s);

}  // namespace pb
