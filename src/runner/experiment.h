// Experiment configs (YAML) and the trials they expand to. PCL-free.
//
// An experiment names scenes (a generator config to render, or an existing
// BOP dataset), the object, descriptors x refinements x a parameter grid, the
// added noise levels and thresholds. Trials are the cartesian product over
// scene images, descriptors, refinements, grid points and noise levels.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

#include "core/hash.h"
#include "core/yaml.h"
#include "io/bop.h"
#include "recognition/settings.h"

namespace pb {

struct SceneSource {
  std::string name;          // label used in tables (e.g. "table_astra")
  std::string generate;      // generator config path ("" when dataset is given)
  // Point clouds (.pcd, .ply; relative to the config) made into a dataset by
  // `posebench import-clouds` (scenes/import_clouds.h) before the run, one
  // image each; `cloud` holds its options: units (auto, mm, m), intrinsics
  // ("fx,fy,cx,cy[,width,height]") or camera (a camera.json).
  std::vector<std::string> clouds;
  nlohmann::json cloud = nlohmann::json::object();
  std::string dataset;       // BOP dataset root (after generation: scenes/<name>...)
  std::string split = "test";
  std::vector<int> scene_ids;  // empty = all scenes of the split
  int images = 0;              // first N images per scene (0 = all)
  int image_stride = 1;        // every K-th image per scene (video sequences), before `images`
  // A BOP test-targets file (e.g. test_targets_bop19.json; relative to the
  // dataset root): only the images it lists for the experiment's object are
  // trials, and scene_ids defaults to their scenes. "" = every image.
  std::string targets;
  // The name of the scene set this one is the twin of (`posebench twin`):
  // the report pairs their trials ("Real and twin"). "" = none.
  std::string twin_of;
  // `twin: {sensor, keep_background, seed}`: the scene set is made by
  // `posebench twin` from the twin_of set's dataset with this sensor (a
  // built-in name or a profile file) before the run; it takes that set's
  // split, scene_ids, images, targets and scenario. Empty sensor = not a
  // generated twin.
  std::string twin_sensor;
  bool twin_keep_background = false;
  uint64_t twin_seed = 1;
  std::string scenario = "";   // table | warehouse: picks the translation threshold
  // Refinements for this scene set, replacing the experiment's list (the
  // thesis used ICP point-to-plane in the warehouse, point-to-point on tables).
  std::vector<std::string> refinements;
  // Overrides of the scene config (`generator:`), merged into it section by
  // section (JSON merge patch): {images: 60}, {warehouse: {wall: true}}.
  nlohmann::json generator_overrides = nlohmann::json::object();
  // The recognition settings of this scene's trials: the experiment's
  // `settings` with the scene's own `settings` read over them (as in the
  // thesis's per-scenario Tables 4.2 and 4.8).
  RecognitionSettings settings;
};

struct Thresholds {
  double table_translation_mm = 50.0;       // thesis: 50 mm in the table scenario
  double warehouse_translation_mm = 100.0;  // thesis: 100 mm in the warehouse scenario
  double rotation_1mpq = 0.05;              // thesis: 1 - |p.q| < 0.05
};

// A second judgement of every pose (experiment `judgements:`): the thesis's
// errors and thresholds over another symmetry set than the model's own, e.g.
// the milk carton's "faces on faces" (the 8 rotations of its body). Each
// record carries judgements.NAME.
struct Judgement {
  std::string name;
  std::string description;
  std::vector<Mat4> symmetries_discrete;                 // model frame, mm
  std::vector<ContinuousSymmetry> symmetries_continuous;
};

// ExperimentConfig::object that takes every object of each scene's BOP test
// targets (one trial per target, recognizing up to its inst_count).
inline constexpr const char* kEveryTargetObject = "all";
// The test targets a generated scene set lists (`generate` writes them; with
// `object: all` a generated scene takes them).
inline constexpr const char* kGeneratedTargets = "test_targets_bop19.json";

// One axis of the parameter grid: a setting's dotted path (e.g.
// "global.top_k") and its values, each applied over a scene's settings by
// apply_setting (recognition/settings.h).
struct GridAxis {
  std::string path;
  std::vector<YamlNode> values;  // the config's own nodes (errors name their line)
};

struct ExperimentConfig {
  std::string file;                 // the YAML it came from
  std::string name;                 // experiment name (default: file stem)
  uint64_t seed = 1;                // seeds every trial (derive_seed with the trial key)
  std::string object;               // registry name / BOP object name or id; "all": every test target's
  std::vector<SceneSource> scenes;
  std::vector<std::string> descriptors;
  std::vector<std::string> refinements{"icp"};
  std::vector<GridAxis> grid;       // the parameter grid, in declaration order
  std::vector<double> added_noise_mm{0.0};  // extra Gaussian depth noise per trial
  RecognitionSettings settings;     // the recognition settings of `settings:` (each scene's start from them)
  Thresholds thresholds;
  double timeout_s = 300;           // a trial running longer is recorded as "timeout"
  bool registration_only = false;   // Table 4.9: refine from perturbed ground truth
  double perturb_deg = 10, perturb_mm = 20;  // registration_only perturbation
  // How to report: {reference_table: "4.1", plot_x: "added_noise_mm",
  // columns: descriptor | refinement | method}. Part of the hash.
  nlohmann::json report = nlohmann::json::object();
  std::vector<Judgement> judgements;
  std::string hash;                 // hash of the canonical config (results folder guard)
  nlohmann::json canonical;         // the parsed config as JSON
};

// Parses and validates; InputError naming file, line and key on any problem.
ExperimentConfig load_experiment(const std::string& path);

// The `judgements:` section (name -> {description, symmetries_discrete,
// symmetries_continuous}, BOP-style as in models.yaml).
std::vector<Judgement> parse_judgements(const YamlNode& section);
// As JSON for experiment.json: [{name, symmetries_discrete, symmetries_continuous}].
nlohmann::json judgements_json(const std::vector<Judgement>& judgements);

struct Trial {
  std::string key;        // unique, stable: scene/image/descriptor/refinement/params/noise
  std::string scene_name; // SceneSource::name
  std::string scenario;   // table | warehouse
  std::string dataset, split;
  int scene_id = 0, im_id = 0;
  int obj_id = 0;          // `object: all`: the test target's object (0: the experiment's object)
  int inst_count = 0;      // `object: all`: the target's instance count (0: one estimate)
  std::string descriptor, refinement;
  nlohmann::json params;  // grid point: dotted path -> value
  double added_noise_mm = 0;
  RecognitionSettings settings;  // the trial's settings, lengths still relative (resolve_for_scene)
  uint64_t seed = 0;
};

// Expands the experiment to its trials, in a fixed order. Scenes must have
// their dataset materialized (see prepare_scenes in runner.h).
std::vector<Trial> expand_trials(const ExperimentConfig& cfg);


}  // namespace pb
