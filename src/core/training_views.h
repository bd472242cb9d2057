// Training views: the model rendered alone from chosen viewpoints (the
// thesis's "model views"), as data. scenes/views.h renders them from a
// ViewSettings; recognition trains on whatever views it is given, so it
// needs neither the renderer nor OSMesa.
#pragma once

#include <string>
#include <vector>

#include "core/settings_fields.h"
#include "core/types.h"

namespace pb {

// Where the training views are rendered from (the `views:` settings section).
struct ViewSettings {
  // 1: one side view; 8: a ring of 8 around the vertical axis; 12: the ring
  // plus 4 from below (as the thesis); any other N: N viewpoints spread
  // evenly over a sphere (Fibonacci tessellation).
  int views = 12;
  double elevation_deg = 20.0;   // ring elevation above the horizontal plane
  double side_elevation_deg = 0.0;    // the single side view (views = 1): no top, no bottom
  double below_elevation_deg = -45.0; // the 4 extra views of views = 12 (from below)
  // true: the ring (elevation_deg) and the single view (side_elevation_deg)
  // are rendered from the middle of the scene set's camera elevation range
  // (`camera.elevation_deg` of the scene config that generated it, read
  // from its posebench_scene.json), so the model is trained as the scenes
  // see it. Only for generated scene sets; the 4 views from below stay.
  bool follow_scene = false;
  double distance_factor = 3.0;  // camera distance = factor * bounding-box diagonal (>= diameter)
  int resolution = 256;          // square image, pixels
  double fov_deg = 30.0;         // field of view, degrees

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("views", s.views, fields::at_least(1));
    f("elevation_deg", s.elevation_deg, fields::in_range(-90, 90));
    f("side_elevation_deg", s.side_elevation_deg, fields::in_range(-90, 90));
    f("below_elevation_deg", s.below_elevation_deg, fields::in_range(-90, 90));
    f("follow_scene", s.follow_scene);
    f("distance_factor", s.distance_factor, fields::positive());
    f("resolution", s.resolution, fields::in_range(8, 4096));
    f("fov_deg", s.fov_deg, fields::positive());
  }
  void validate(const YamlNode& node) const {
    if (fov_deg >= 170) node["fov_deg"].fail("must be below 170");
  }
};

// A view of a model rendered alone: an organized cloud in the view's camera
// frame and the pose that produced it.
struct TrainingView {
  Intrinsics K;
  DepthImage depth;       // mm, 0 where the model is not
  OrganizedCloud cloud;   // from depth, camera frame
  Pose T_cam_model;       // model -> this view's camera
};

// The training views of one model, or none and why (empty or degenerate mesh).
struct TrainingViews {
  std::string model_name;            // for messages and cache file names
  std::vector<TrainingView> views;
  std::string empty_reason;          // set when views is empty
  double diameter_mm = 0;            // the model's diameter (mm), what relative lengths ("0.05d")
                                     // refer to; 0 = unknown (train_model then takes the
                                     // bounding-box diagonal of the views in the model frame)
};

}  // namespace pb
