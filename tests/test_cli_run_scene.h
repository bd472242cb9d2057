// The small, fast scene set the `posebench run` tests generate
// (test_cli_run*.cpp): synthetic sensor, 3 table images of the LS5, few
// distractors.
#pragma once

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

}  // namespace pbcli
