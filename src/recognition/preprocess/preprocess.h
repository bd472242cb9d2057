// Preprocessing (THESIS.md "Shared preprocessing"): depth -> cloud, range
// cut, voxel grid, dominant plane removal (RANSAC), normals toward the
// viewpoint. The same steps prepare the model's training views.
#pragma once

#include "core/types.h"
#include "core/yaml.h"
#include "recognition/cloud.h"

namespace pb {

struct PreprocessSettings {
  double min_range_mm = 100.0;      // points closer than this are dropped
  double max_range_mm = 3000.0;     // far points cut (thesis: "cut by range")
  double voxel_mm = 10.0;           // downsampling voxel (Table 4.2: 20 warehouse, 10 table)
  bool remove_plane = true;         // remove the dominant plane (floor / table)
  double plane_threshold_mm = 10.0; // RANSAC inlier distance for the plane
  int plane_iterations = 200;       // RANSAC iterations
  double min_plane_fraction = 0.2;  // remove the plane only if it holds this fraction
  double normal_radius_mm = 20.0;   // PCA neighbourhood radius for normals
};

void parse_preprocess(const YamlNode& node, PreprocessSettings& s);

// Scene preprocessing. Every random choice (RANSAC) draws from `seed`.
PointSet preprocess_scene(const OrganizedCloud& cloud, const PreprocessSettings& s, uint64_t seed);
// Training view preprocessing: no plane removal (the model is alone).
PointSet preprocess_view(const OrganizedCloud& cloud, const PreprocessSettings& s, uint64_t seed);

}  // namespace pb
