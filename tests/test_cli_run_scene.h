// The small, fast scene set the `posebench run` tests generate
// (test_cli_run*.cpp): synthetic sensor, 3 table images of the LS5, few
// distractors.
#pragma once

#include <string>

#include "cli_test_util.h"

namespace pbcli {

inline const char* kSmallTableScene = R"(scenario: table
seed: 77
images: 3
sensor: {name: custom, width: 320, height: 320, hfov_deg: 30, vfov_deg: 30}
noise: {model: gaussian, sigma_mm: 1.0}
target: ls5
target_upright_probability: 1.0
distractors: {pool: [box_small, cylinder], count: [2, 3]}
occlusion: none
camera: {distance_mm: [700, 900], elevation_deg: [40, 60]}
)";

// An experiment on that scene set (its config at `scene_yaml`): the LS5, the
// given descriptors ("[cvfh, esf]") with ICP, 4 training views.
inline std::string small_experiment_yaml(const std::string& name, const std::string& scene_yaml,
                                         const std::string& descriptors) {
  return "name: " + name + "\nseed: 3\nobject: ls5\nscenes:\n  - name: table_small\n    generate: " + scene_yaml +
         "\n    scenario: table\ndescriptors: " + descriptors + "\nrefinements: [icp]\nsettings:\n  views: {views: 4}\n";
}

// Writes the scene and experiment configs into `dir` and runs the
// experiment into DIR/res (cache and scenes under `dir` too).
inline Run run_small_experiment(const std::string& dir, const std::string& name, const std::string& descriptors) {
  write_file(dir + "/scene.yaml", kSmallTableScene);
  write_file(dir + "/exp.yaml", small_experiment_yaml(name, dir + "/scene.yaml", descriptors));
  return run("run exp.yaml --out res -q --cache cache --scenes scenes", dir);
}

}  // namespace pbcli
