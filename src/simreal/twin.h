// Twin scenes: a synthetic BOP dataset with one image per real image of a
// dataset with ground truth (`posebench twin`). Each twin image has the real
// image's intrinsics and depth scale, the annotated objects at their GT
// poses and the supporting plane fitted to the real depth, rendered and
// degraded by a sensor profile; with keep_background the real depth stays
// wherever no GT object is drawn, so that only the sensor model on the
// objects differs. Running an experiment on both sets measures the
// sim-to-real gap per method (report: "Real and twin").
#pragma once

#include <cstdint>
#include <string>

#include "render/sensor.h"

namespace pb {

struct TwinSettings {
  std::string split = "test";
  bool keep_background = false;  // real depth outside the GT objects' rendered masks
  uint64_t seed = 1;             // the noise of image (scene, im) draws from derive_seed(seed, {scene, im})
  int max_images = 0;            // 0 = every image with depth and GT
  double plane_inlier_mm = 8.0;  // RANSAC band of the supporting plane
};

struct TwinSummary {
  int images = 0;
  int planes_found = 0;  // images whose supporting plane was found and drawn
};

// Writes the twin of `real_root` into out_dir (atomically: OUT.partial,
// then renamed): camera.json and models/ copied, test/SCENE/{depth,
// scene_camera.json, scene_gt.json, scene_gt_info.json}, the real set's
// test_targets_bop19.json restricted to the twin's images, and
// posebench_twin.json (the real set, the profile, the settings, each image's
// plane). The sensor's intrinsics are replaced by each image's.
TwinSummary write_twin(const std::string& real_root, const SensorProfile& sensor, const TwinSettings& s,
                       const std::string& out_dir);

}  // namespace pb
