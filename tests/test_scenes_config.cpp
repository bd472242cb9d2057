// Scene config parsing: defaults per scenario, ranges, and errors that name
// the file, the field and the line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/yaml.h"
#include "scenes/scene_config.h"

using namespace pb;

namespace {

SceneSettings parse(const std::string& yaml) {
  return parse_scene_settings(YamlNode::load_string(yaml, "cfg.yaml"));
}

// Expects an InputError naming the file and `field`; returns its message.
std::string error_of(const std::string& yaml, const std::string& field) {
  try {
    parse(yaml);
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "cfg.yaml") << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << yaml;
  return "";
}

}  // namespace

TEST(SceneConfig, DefaultsPerScenario) {
  const SceneSettings t = parse("scenario: table\n");
  EXPECT_EQ(t.images, 30);
  EXPECT_EQ(t.target, "ls5");
  EXPECT_EQ(t.camera.distance_mm.lo, 600);
  EXPECT_EQ(t.camera.distance_mm.hi, 1500);
  EXPECT_EQ(t.camera.elevation_deg.lo, 30);
  EXPECT_EQ(t.camera.elevation_deg.hi, 70);
  EXPECT_EQ(t.distractors.min_count, 3);
  EXPECT_EQ(t.distractors.max_count, 8);
  EXPECT_EQ(t.sensor.K.width, 512);
  EXPECT_EQ(t.noise.model, "gaussian");
  EXPECT_DOUBLE_EQ(t.noise.gaussian.sigma_mm, 1.0);
  EXPECT_FALSE(t.occlusion.enabled);
  const SceneSettings w = parse("scenario: warehouse\ndistractors: {pool: [pallet]}\n");
  EXPECT_EQ(w.camera.distance_mm.lo, 2000);
  EXPECT_EQ(w.camera.distance_mm.hi, 5000);
  EXPECT_EQ(w.distractors.min_count, 0);
  EXPECT_EQ(w.distractors.max_count, 2);
  EXPECT_EQ(w.warehouse.object_size_mm.lo, 1000);
  EXPECT_EQ(w.warehouse.object_size_mm.hi, 1500);
}

TEST(SceneConfig, FullConfig) {
  const SceneSettings s = parse(R"(
scenario: table
seed: 42
images: 5
scene_id: 7
sensor: astra
noise: {model: gaussian, sigma_mm: 2.5}
depth_scale: 0.25
target: milk_carton
distractors: {pool: [boletus, cylinder], count: [2, 4], upright_probability: 1.0}
occlusion: [0.5, 0.7]
camera: {distance_mm: 800, elevation_deg: [40, 50]}
)");
  EXPECT_EQ(s.seed, 42u);
  EXPECT_EQ(s.images, 5);
  EXPECT_EQ(s.scene_id, 7);
  EXPECT_EQ(s.sensor.K.width, 640);
  EXPECT_EQ(s.noise.model, "gaussian");
  EXPECT_DOUBLE_EQ(s.noise.gaussian.sigma_mm, 2.5);
  EXPECT_DOUBLE_EQ(s.depth_scale, 0.25);
  EXPECT_EQ(s.target, "milk_carton");
  EXPECT_EQ(s.distractors.pool.size(), 2u);
  EXPECT_EQ(s.distractors.min_count, 2);
  EXPECT_EQ(s.distractors.max_count, 4);
  EXPECT_TRUE(s.occlusion.enabled);
  EXPECT_DOUBLE_EQ(s.occlusion.visib_fract.lo, 0.5);
  EXPECT_DOUBLE_EQ(s.occlusion.visib_fract.hi, 0.7);
  EXPECT_DOUBLE_EQ(s.camera.distance_mm.lo, 800);
  EXPECT_DOUBLE_EQ(s.camera.distance_mm.hi, 800);
  EXPECT_NE(scene_settings_json(s).find("\"seed\": 42"), std::string::npos);
}

TEST(SceneConfig, Errors) {
  std::string m = error_of("scenario: table\ncolour: red\n", "colour");
  EXPECT_NE(m.find("line 2"), std::string::npos) << m;
  error_of("scenario: kitchen\n", "scenario");
  error_of("images: 3\n", "scenario");
  error_of("scenario: table\nimages: -3\n", "images");
  error_of("scenario: table\ncamera: {distance_mm: [-600, 1500]}\n", "camera.distance_mm");
  error_of("scenario: table\ncamera: {distance_mm: [1500, 600]}\n", "camera.distance_mm");
  error_of("scenario: table\ncamera: {zoom: 2}\n", "camera.zoom");
  error_of("scenario: table\ntable: {size_mm: -4}\n", "table.size_mm");
  error_of("scenario: table\ntable: {floor_drop_mm: 10}\n", "table.floor_drop_mm");  // inside the table top
  error_of("scenario: table\ntable: {wall_distance_mm: [-5, 100]}\n", "table.wall_distance_mm");
  error_of("scenario: warehouse\nwarehouse: {object_size_mm: [-1, 2]}\ndistractors: {pool: [pallet]}\n",
           "warehouse.object_size_mm");
  error_of("scenario: table\nocclusion: [0.4, 1.5]\n", "occlusion");
  error_of("scenario: table\nocclusion: sometimes\n", "occlusion");
  error_of("scenario: table\ndistractors: {pool: [], count: [3, 8]}\n", "distractors");
  error_of("scenario: table\ndistractors: {pool: [boletus], count: [-1, 2]}\n", "distractors.count");
  error_of("scenario: table\ntarget_upright_probability: 2\n", "target_upright_probability");
  error_of("scenario: table\ntarget_free_probability: -0.5\n", "target_free_probability");
  error_of("scenario: table\ntarget_tilt_deg: 95\n", "target_tilt_deg");
  // A key given twice (yaml-cpp keeps the first silently).
  m = error_of("scenario: table\ntarget_tilt_deg: 5\nimages: 3\ntarget_tilt_deg: 10\n", "target_tilt_deg");
  EXPECT_NE(m.find("key given twice, at lines 2 and 4"), std::string::npos) << m;
  error_of("scenario: table\ncamera: {distance_mm: [600, 900], distance_mm: [700, 800]}\n", "camera.distance_mm");
  error_of("scenario: table\ntarget_tilt_deg: -1\n", "target_tilt_deg");
  error_of("scenario: table\nimages: many\n", "images");
  // A key that is not a plain name (found by fuzz/fuzz_scene_yaml.cpp:
  // yaml-cpp's BadConversion escaped as an internal error).
  m = error_of("scenario: table\n? [80, 20]\n: 3\n", "");
  EXPECT_NE(m.find("a key must be a plain name"), std::string::npos) << m;
  m = error_of("scenario: table\nsensor: lidar9000\n", "sensor");
  EXPECT_NE(m.find("lidar9000"), std::string::npos) << m;
}

TEST(SceneConfig, MalformedYamlNamesTheFile) {
  const std::string dir = std::filesystem::temp_directory_path() / "posebench_cfg_test";
  std::filesystem::create_directories(dir);
  const std::string f = dir + "/broken.yaml";
  std::ofstream(f) << "scenario: table\ncamera: {distance_mm: [600, 1500\n";
  try {
    load_scene_settings(f);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), f);
    EXPECT_NE(std::string(e.what()).find("line"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(SceneConfig, RegistryRelativeToConfig) {
  const SceneSettings s = parse_scene_settings(
      YamlNode::load_string("scenario: table\nregistry: ../models/models.yaml\n", "/a/b/configs/cfg.yaml"));
  EXPECT_EQ(s.registry, "/a/b/models/models.yaml");
  EXPECT_EQ(s.name, "cfg");
}

TEST(SceneConfig, LayoutDetailsDefaultsAndParsing) {
  const SceneSettings t = parse("scenario: table\n");
  EXPECT_EQ(t.camera.near_mm, 50);
  EXPECT_EQ(t.camera.far_mm, 40000);
  EXPECT_EQ(t.distractors.placement_tries, 60);
  EXPECT_EQ(t.occlusion.box_depth_mm.lo, 30);
  EXPECT_EQ(t.occlusion.box_depth_mm.hi, 80);
  EXPECT_EQ(t.occlusion.cylinder_min_radius_mm, 20);
  EXPECT_EQ(t.occlusion.search_iterations, 12);
  const SceneSettings w = parse("scenario: warehouse\ndistractors: {pool: [pallet]}\n");
  EXPECT_EQ(w.occlusion.box_depth_mm.lo, 300);
  EXPECT_EQ(w.occlusion.box_depth_mm.hi, 800);
  EXPECT_EQ(w.occlusion.cylinder_min_radius_mm, 150);
  EXPECT_EQ(w.warehouse.wall_yaw_deg, 15);

  const SceneSettings s = parse(R"(
scenario: warehouse
distractors: {pool: [pallet], placement_tries: 10, image_margin: 0}
camera: {near_mm: 100, far_mm: 20000, clearance_mm: 0}
occlusion: {visib_fract: [0.5, 0.8], box_probability: 1, box_depth_mm: [100, 200], lateral_offset: [-1, 0],
            search_iterations: 20, cylinder_segments: 64}
warehouse: {wall_yaw_deg: 0, floor_thickness_mm: 50}
)");
  EXPECT_EQ(s.distractors.placement_tries, 10);
  EXPECT_EQ(s.distractors.image_margin, 0);
  EXPECT_EQ(s.camera.near_mm, 100);
  EXPECT_EQ(s.camera.far_mm, 20000);
  EXPECT_EQ(s.camera.clearance_mm, 0);
  EXPECT_EQ(s.occlusion.box_probability, 1);
  EXPECT_EQ(s.occlusion.box_depth_mm.lo, 100);
  EXPECT_EQ(s.occlusion.lateral_offset.lo, -1);
  EXPECT_EQ(s.occlusion.search_iterations, 20);
  EXPECT_EQ(s.occlusion.cylinder_segments, 64);
  EXPECT_EQ(s.warehouse.wall_yaw_deg, 0);
  EXPECT_EQ(s.warehouse.floor_thickness_mm, 50);

  error_of("scenario: table\ncamera: {near_mm: 100, far_mm: 50}\n", "camera.far_mm");
  error_of("scenario: table\noccluson: {box_probability: 2}\n", "occluson");
  error_of("scenario: table\nocclusion: {box_probability: 2}\n", "occlusion.box_probability");
  error_of("scenario: table\nocclusion: {box_colour: red}\n", "occlusion.box_colour");
  error_of("scenario: table\nocclusion: {footprint_sides: 2}\n", "occlusion.footprint_sides");
  error_of("scenario: table\ndistractors: {placement_tries: 0}\n", "distractors.placement_tries");
  EXPECT_EQ(t.distractors.spread_max_radii, 0);  // no cap
  EXPECT_EQ(parse("scenario: table\ndistractors: {spread_min_radii: 2, spread_max_radii: 2.5}\n")
                .distractors.spread_max_radii,
            2.5);
  error_of("scenario: table\ndistractors: {spread_max_radii: 2}\n", "distractors.spread_max_radii");  // < 3
  error_of("scenario: table\ndistractors: {spread_max_radii: -1}\n", "distractors.spread_max_radii");
  error_of("scenario: table\nwarehouse: {wall_yaw_deg: 95}\n", "warehouse.wall_yaw_deg");
}

TEST(SceneConfig, LayoutDetailsInJsonOnlyWhenChanged) {
  const std::string base = "scenario: table\nocclusion: {visib_fract: [0.4, 0.9]}\n";
  const std::string def = scene_settings_json(parse(base));
  EXPECT_EQ(def.find("\"near_mm\""), std::string::npos) << def;
  EXPECT_EQ(def.find("box_probability"), std::string::npos) << def;
  const std::string changed = scene_settings_json(
      parse("scenario: table\nocclusion: {visib_fract: [0.4, 0.9], box_probability: 0.5}\ncamera: {near_mm: 60}\n"));
  EXPECT_NE(changed.find("\"box_probability\": 0.5"), std::string::npos) << changed;
  EXPECT_NE(changed.find("\"near_mm\": 60"), std::string::npos) << changed;
  EXPECT_EQ(changed.find("\"far_mm\""), std::string::npos) << changed;
  EXPECT_EQ(def.find("spread_max_radii"), std::string::npos) << def;
  const std::string capped = scene_settings_json(parse("scenario: table\ndistractors: {spread_max_radii: 4}\n"));
  EXPECT_NE(capped.find("\"spread_max_radii\": 4"), std::string::npos) << capped;
}
