// Local pipeline settings (FPFH, SHOT, 3D Hough voting). THESIS.md "Local
// pipeline"; defaults are the table synthetic values of Table 4.2.
#pragma once

#include "core/yaml.h"

namespace pb {

struct LocalSettings {
  double keypoint_voxel_mm = 15.0;      // second, coarser voxel grid (Table 4.2)
  double descriptor_radius_mm = 40.0;   // FPFH / SHOT support radius
  double lrf_radius_mm = 40.0;          // local reference frame radius (Hough voting)
  double match_threshold = 0.25;        // max descriptor distance (squared L2 for SHOT,
                                        // as PCL's tutorial; scaled per descriptor)
  int matches_per_keypoint = 1;         // nearest model descriptors kept per scene keypoint
  double hough_bin_mm = 50.0;           // 3D Hough bin size (Table 4.2)
  int hough_min_votes = 5;              // minimum votes for a hypothesis (thesis: 5)
  int max_hypotheses = 10;              // at most this many clusters go on to refinement
};

void parse_local(const YamlNode& node, LocalSettings& s);

}  // namespace pb
