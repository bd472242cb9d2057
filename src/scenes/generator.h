// Scene generators: table and warehouse scenes with ground truth, written in
// the BOP layout (io/bop.h).
//
// Per image, every random choice draws from Rng(derive_seed(seed, {scene_id,
// im_id, attempt})) (layout) and Rng(derive_seed(seed, {scene_id, im_id,
// kNoiseStream})) (sensor noise), so images are independent of each other and
// the same settings give the same bytes.
//
// Layout (world frame: z up, the table top / floor at z = 0):
//  1. target: a rest pose of its mesh (scenes/rest_poses.h; upright with
//     target_upright_probability) with a random yaw, at the origin;
//  2. camera: distance, elevation and azimuth drawn from camera.*, looking at
//     the target's centre (shifted by look_jitter in the image plane);
//  3. occluder (occluded images): a box or cylinder standing between camera
//     and target; its height is bisected until the target's visible fraction
//     reaches a value drawn from occlusion.visib_fract;
//  4. other objects: rest poses, random yaw, at the ground point seen through
//     a random pixel, footprints (2D convex hulls) not overlapping;
//  5. table: a flat box under everything; warehouse: a floor and a wall
//     behind the target.
// A layout whose target is not visible enough (min_target_visib without an
// occluder, or outside the occlusion range) is resampled (next attempt).
// Objects whose silhouette lies entirely outside the image are left out of
// the ground truth. Table, floor, wall and occluders are not annotated.
// With setups > 0, image i shows set-up i mod setups: its objects drawn
// once from Rng(derive_seed(seed, {scene_id, kSetupStream, k, attempt}))
// (steps 1-5 with a reference camera, accepted as an image would be), and
// only the camera drawn per image (step 2, from the image's stream).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/types.h"
#include "io/bop.h"
#include "scenes/scene_config.h"

namespace pb {

constexpr uint64_t kNoiseStream = 0x6e6f697365ull;  // "noise"
constexpr uint64_t kSetupStream = 0x7365747570ull;  // "setup": set-up k's layout (SceneSettings::setups)

// One generated image.
struct GeneratedImage {
  ImageInfo info;                   // K, depth_scale, ground truth (target first), gt_info
  DepthImage depth;                 // final depth (noise, range cut), mm
  DepthImage depth_clean;           // rendered depth before noise, mm
  std::vector<int32_t> labels;      // per pixel: index into info.gt of the visible object, -1 other
  std::vector<std::string> names;   // registry name per info.gt entry
  // Traceability.
  int attempts = 0;                 // layouts tried
  double camera_distance_mm = 0;
  double camera_elevation_deg = 0;
  double camera_azimuth_deg = 0;
  bool occluded = false;            // an occluder was placed
  double occluder_height_mm = 0;
  Pose T_world_cam;                 // camera pose in the scene's world frame (z up)
};

// A model as used in the data set (millimetres, possibly scaled for the
// warehouse scenario).
struct SceneModel {
  std::string name;
  int obj_id = 0;
  Mesh mesh;
  ModelInfo info;
  double scale = 1.0;  // applied to the registry's mesh
};

class SceneGenerator {
 public:
  // Loads the target and pool models from the registry (InputError if one is
  // unknown or its mesh is missing) and computes their rest poses.
  explicit SceneGenerator(const SceneSettings& settings);
  ~SceneGenerator();
  SceneGenerator(const SceneGenerator&) = delete;
  SceneGenerator& operator=(const SceneGenerator&) = delete;

  // Generates image `im_id` (0-based). Deterministic in (settings, im_id).
  // InputError naming the config's occlusion/min_target_visib field when no
  // layout satisfies the visibility constraints within max_attempts.
  GeneratedImage generate(int im_id);

  // An independent copy (same models, its own renderer) for another thread.
  std::unique_ptr<SceneGenerator> clone() const;

  const SceneSettings& settings() const;
  const std::vector<SceneModel>& models() const;  // by obj_id, ascending
  const SceneModel& model(const std::string& name) const;

 private:
  struct Impl;
  explicit SceneGenerator(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

struct GenerateSummary {
  std::string out_dir;
  int images = 0;
  int objects = 0;                  // ground-truth instances over all images
  double mean_target_visib = 0;     // mean visib_fract of the target
  double min_target_visib = 0;
  std::string preview_png;          // depth preview of the first image
  double seconds = 0;
};

// The version of what the generator makes from a config: bump it whenever
// the same config gives other images (a sensor model's defaults, the layout,
// the renderer), so that `posebench run`, which keeps one scene set per
// config in its --scenes folder, generates the set again instead of reusing
// an old one. 1 = the sets made before it existed; 2 = the astra sensor
// calibrated on real frames (results/sensors/fit_astra.json); 3 = the
// kinect_one sensor's driver edge filter (TimeOfFlightNoise); 4 = the
// kinect_one sensor calibrated on real frames (results/sensors/fit_kinect_one.json).
constexpr int kSceneSetVersion = 4;

// Generates the whole scene set into `out_dir` (BOP layout, see docs/user-guide.md):
// written to `out_dir.partial` and renamed into place at the end, so an
// interrupted or failed run never leaves `out_dir` looking complete (a failed
// run removes its partial output). An existing `out_dir` is replaced only if
// it is a posebench scene set (has posebench_scene.json); otherwise
// InputError. `progress` (may be null) is called after each image. Images
// are generated by `threads` workers (each its own renderer); the output is
// the same for any number.
GenerateSummary generate_dataset(const SceneSettings& settings, const std::string& out_dir,
                                 void (*progress)(int done, int total) = nullptr, int threads = 1);

// Colour-mapped depth (near = warm, far = cool, black = no depth) as RGB8;
// with intrinsics also shaded by the surface normal.
std::vector<uint8_t> depth_preview_rgb(const DepthImage& depth, const Intrinsics* K = nullptr);

}  // namespace pb
