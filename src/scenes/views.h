// Training views: the model rendered alone from chosen viewpoints (the
// thesis's "model views"). Each view is an organized cloud in its own camera
// frame with the pose T_cam_model that produced it.
#pragma once

#include <string>
#include <vector>

#include "core/training_views.h"
#include "core/types.h"

namespace pb {


// Unit directions from the model origin to each camera (model frame, z up),
// in the order render_training_views uses. InputError on bad settings.
std::vector<Vec3> view_directions(const ViewSettings& settings);

std::vector<TrainingView> render_training_views(const Mesh& mesh, const ViewSettings& settings);

// `settings` with follow_scene resolved for the scene set at dataset_root:
// elevation_deg and side_elevation_deg set to the middle of the set's camera
// elevation range (ROOT/posebench_scene.json, settings.camera.elevation_deg)
// and follow_scene cleared, so the result names the views it renders.
// Unchanged when follow_scene is false. InputError naming the file and the
// field when the set has no such file or range (e.g. a BOP data set not made
// by `posebench generate`).
ViewSettings views_for_scene_set(const ViewSettings& settings, const std::string& dataset_root);
// Its two halves: the middle of the set's camera elevation range (reads
// ROOT/posebench_scene.json; the same InputError), and `settings` with the
// ring and the single view at `elevation_deg` and follow_scene cleared.
double scene_set_elevation_deg(const std::string& dataset_root);
ViewSettings views_at_elevation(const ViewSettings& settings, double elevation_deg);

// The training views recognition learns from (train_model): rendered, or
// none with the reason when the mesh is empty or degenerate.
TrainingViews training_views(const Mesh& mesh, const ViewSettings& settings, const std::string& model_name);

// A model given as a point cloud (mm) instead of a mesh: a scan of the
// object from one side, in the frame of the camera that saw it (as PCL's
// tutorial models are). Its model frame: the camera's axes, the origin at
// the centre of the points' bounding box (as BOP places a model's origin).
Pose cloud_model_pose(const std::vector<Vec3f>& points_cam);  // T_cam_model of that one view
// Its one training view: the points as that camera saw them, through a
// virtual 640 x 480 camera fitted to their extent (io/cloud.h), so that
// nearly every point keeps a pixel of its own. None, with the reason, when
// no point lies in front of the camera.
TrainingViews cloud_training_views(const std::vector<Vec3f>& points_cam, const std::string& model_name);

}  // namespace pb
