// The BOP dataset layout (../shared/reference/bop_datasets_format.md): one
// reader for datasets written by posebench's generator and for real BOP
// datasets, and the writer the generator uses.
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

struct ContinuousSymmetry {
  Vec3 axis = Vec3::UnitZ();    // unit axis in the model frame
  Vec3 offset = Vec3::Zero();   // a point on the axis (mm)
};

// One entry of models/models_info.json.
struct ModelInfo {
  int obj_id = 0;
  std::string name;            // posebench extension ("name"); empty in real BOP sets
  double diameter = 0;         // mm, largest vertex-to-vertex distance
  Vec3 min = Vec3::Zero();     // bounding box min (min_x, min_y, min_z)
  Vec3 size = Vec3::Zero();    // bounding box size (size_x, ...)
  std::vector<Mat4> symmetries_discrete;  // 4x4, translation in mm
  std::vector<ContinuousSymmetry> symmetries_continuous;
};

// One ground-truth object instance in an image (scene_gt.json).
struct GtObject {
  int obj_id = 0;
  Pose T_cam_model;  // cam_R_m2c, cam_t_m2c
};

// Per ground truth statistics (scene_gt_info.json).
// scene_gt_info.json, every field optional when read (see read_scene_json).
struct GtInfo {
  std::array<int, 4> bbox_obj{{-1, -1, 0, 0}};    // x, y, w, h; (-1, -1, 0, 0) = not given
  std::array<int, 4> bbox_visib{{-1, -1, 0, 0}};
  int px_count_all = 0;    // -1 = not given (when read)
  int px_count_valid = 0;
  int px_count_visib = 0;
  double visib_fract = 0;  // NaN = unknown (when read)
};

struct ImageInfo {
  int im_id = 0;
  Intrinsics K;
  double depth_scale = 1.0;         // depth_png * depth_scale = mm
  std::vector<GtObject> gt;         // may be empty (no ground truth)
  std::vector<GtInfo> gt_info;      // empty or parallel to gt
};

struct SceneInfo {
  int scene_id = 0;
  std::map<int, ImageInfo> images;  // by im_id
};

// Read access to a dataset root (DIR with models/ and SPLIT/ folders).
class BopDataset {
 public:
  // Throws InputError naming the path if it is not a BOP dataset
  // (no models/models_info.json or no split folder).
  explicit BopDataset(std::string root);

  const std::string& root() const { return root_; }
  std::vector<std::string> splits() const;
  std::vector<int> scene_ids(const std::string& split) const;
  SceneInfo load_scene(const std::string& split, int scene_id) const;
  DepthImage load_depth(const std::string& split, int scene_id, const ImageInfo& im) const;
  const std::map<int, ModelInfo>& models() const { return models_; }
  const ModelInfo& model_info(int obj_id) const;        // InputError if unknown
  int resolve_object(const std::string& name_or_id) const;  // "3", "obj_000003" or a name
  Mesh load_model(int obj_id) const;                     // models/obj_XXXXXX.ply (mm)
  std::string model_path(int obj_id) const;
  std::string scene_dir(const std::string& split, int scene_id) const;  // ROOT/SPLIT/NNNNNN
  // camera.json of the root, when present (image size and sensor intrinsics).
  const std::optional<Intrinsics>& camera() const { return camera_; }
  double camera_depth_scale() const { return camera_depth_scale_; }

 private:
  std::string root_;
  std::map<int, ModelInfo> models_;
  std::optional<Intrinsics> camera_;
  double camera_depth_scale_ = 1.0;
};

// Writing a dataset. Each JSON file is written atomically (temp + rename).
std::map<int, ModelInfo> read_models_info(const std::string& path);
void write_models_info(const std::string& path, const std::map<int, ModelInfo>& models);
void write_camera_json(const std::string& path, const Intrinsics& K, double depth_scale);
// Reads camera.json (fx, fy, cx, cy, width, height, depth_scale).
Intrinsics read_camera_json(const std::string& path, double* depth_scale = nullptr);
// Writes scene_camera.json, scene_gt.json and scene_gt_info.json of a scene
// folder from its images (creates the folder; scene_gt_info.json only when
// some image has gt_info). Image width/height are not part of BOP's
// scene_camera.json: readers take them from camera.json or the depth PNG
// (BopDataset::load_scene does); read_scene_json leaves them 0.
void write_scene_json(const std::string& scene_dir, const SceneInfo& scene);
SceneInfo read_scene_json(const std::string& scene_dir);

// One entry of a BOP test-targets file (test_targets_bop19.json): an object
// to localize in an image and how many instances of it the image holds.
struct TestTarget {
  int scene_id = 0;
  int im_id = 0;
  int obj_id = 0;
  int inst_count = 0;  // >= 1
};
// Reads a test-targets file: a JSON list of {scene_id, im_id, obj_id,
// inst_count}, every field required, ids >= 0, inst_count >= 1. InputError
// naming the file and the entry ("[3].obj_id") on any problem.
std::vector<TestTarget> read_test_targets(const std::string& path);
// The test targets of a scene by BOP 2019's rule: per image and object, the
// instances visible at least min_visib_fract (scene_gt_info's visib_fract;
// BOP: 0.1), an entry when there is one or more; sorted by image, then
// object. Images without gt_info give none.
std::vector<TestTarget> scene_test_targets(const SceneInfo& scene, double min_visib_fract = 0.1);
// Writes a test-targets file (the list read_test_targets reads).
void write_test_targets(const std::string& path, const std::vector<TestTarget>& targets);

std::string bop_id(int id);  // 6 digits: 000042
// SCENE_DIR/depth/IIIIII.png
std::string bop_depth_path(const std::string& scene_dir, int im_id);

}  // namespace pb
