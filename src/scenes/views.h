// Training views: the model rendered alone from chosen viewpoints (the
// thesis's "model views"). Each view is an organized cloud in its own camera
// frame with the pose T_cam_model that produced it.
#pragma once

#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

struct ViewSettings {
  // 1: one side view; 8: a ring of 8 around the vertical axis; 12: the ring
  // plus 4 from below (as the thesis); any other N: N viewpoints spread
  // evenly over a sphere (Fibonacci tessellation).
  int views = 12;
  double elevation_deg = 20.0;   // ring elevation above the horizontal plane
  double side_elevation_deg = 0.0;    // the single side view (views = 1): no top, no bottom
  double below_elevation_deg = -45.0; // the 4 extra views of views = 12 (from below)
  double distance_factor = 3.0;  // camera distance = factor * bounding-box diagonal (>= diameter)
  int resolution = 256;          // square image, pixels
  double fov_deg = 30.0;         // field of view, degrees
};

struct TrainingView {
  Intrinsics K;
  DepthImage depth;       // mm, 0 where the model is not
  OrganizedCloud cloud;   // from depth, camera frame
  Pose T_cam_model;       // model -> this view's camera
};

// Unit directions from the model origin to each camera (model frame, z up),
// in the order render_training_views uses. InputError on bad settings.
std::vector<Vec3> view_directions(const ViewSettings& settings);

std::vector<TrainingView> render_training_views(const Mesh& mesh, const ViewSettings& settings);

}  // namespace pb
