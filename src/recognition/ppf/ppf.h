// PPF (Drost et al. 2010) settings: PCL's PPFEstimation + PPFRegistration.
#pragma once

#include "core/yaml.h"

namespace pb {

struct PpfSettings {
  int model_points = 300;                 // model downsampled to about this many points
  double angle_step_deg = 12.0;           // discretization of the pair feature angles
  double distance_step_fraction = 0.05;   // distance step as a fraction of the diameter
  double scene_reference_fraction = 0.2;  // fraction of scene points used as references
  double position_cluster_mm = 30.0;      // pose clustering: translation threshold
  double rotation_cluster_deg = 30.0;     // pose clustering: rotation threshold
  int max_hypotheses = 5;                 // clustered poses passed on
};

void parse_ppf(const YamlNode& node, PpfSettings& s);

}  // namespace pb
