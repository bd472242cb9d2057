// PPF (Drost et al. 2010) settings: PCL's PPFEstimation + PPFRegistration.
#pragma once

#include "core/settings_fields.h"

namespace pb {

struct PpfSettings {
  int model_points = 300;                 // model downsampled to about this many points
  double angle_step_deg = 12.0;           // discretization of the pair feature angles
  double distance_step_fraction = 0.05;   // distance step as a fraction of the diameter
  double scene_reference_fraction = 0.2;  // fraction of scene points used as references
  double scene_sampling_steps = 1.0;      // the scene is paired at the model's sampling (Drost et
                                          // al.): voxel-downsampled to this many distance steps
                                          // (distance_step_fraction x diameter) before references
                                          // and pairs are drawn; 0 = the preprocessed scene as is
  double position_cluster_mm = 30.0;      // pose clustering: translation threshold
  double rotation_cluster_deg = 30.0;     // pose clustering: rotation threshold
  int max_hypotheses = 5;                 // clustered poses passed on

  template <class S, class F>
  static void fields(S& s, F& f) {
    // at most 5000: the model's pair features grow with its square
    f("model_points", s.model_points, fields::at_least(10, 5000));
    f("angle_step_deg", s.angle_step_deg, fields::positive(90));
    f("distance_step_fraction", s.distance_step_fraction, fields::positive(1));
    f("scene_reference_fraction", s.scene_reference_fraction, fields::positive(1));
    f("scene_sampling_steps", s.scene_sampling_steps, fields::nonnegative());
    f("position_cluster_mm", s.position_cluster_mm, fields::length(fields::positive()));
    f("rotation_cluster_deg", s.rotation_cluster_deg, fields::positive());
    f("max_hypotheses", s.max_hypotheses, fields::at_least(1));
  }
};

}  // namespace pb
