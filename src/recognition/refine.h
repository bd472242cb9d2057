// Refinement (registration) methods: ICP, ICP-LM, ICP point-to-plane, GICP,
// 3D-NDT, through PCL. Source = the model view, target = the scene (thesis).
#pragma once

#include <string>
#include <vector>

#include "core/types.h"
#include "core/yaml.h"
#include "recognition/cloud.h"

namespace pb {

struct RefineSettings {
  int max_iterations = 40;                 // thesis: at most 40 iterations
  double max_correspondence_mm = 20.0;     // pairs farther apart are rejected
  double transformation_epsilon = 1e-8;    // stop on small change of transform (PCL units)
  double fitness_epsilon = 1e-6;           // stop on small change of mean squared error
  int icp_sample_points = 0;               // ICP point-to-point: random subset of source points (0 = all)
  double ndt_resolution_mm = 20.0;         // NDT grid cell (sized to the object, PCL_NOTES)
  double ndt_step_size_mm = 10.0;          // NDT max More-Thuente step
  double gicp_correspondence_randomness = 20;  // GICP neighbours for covariances
};

void parse_refine(const YamlNode& node, RefineSettings& s);

struct RefineResult {
  Pose T_cam_model;        // refined pose
  bool converged = false;
  double fitness = 0;      // mean squared distance of corresponding points (mm^2)
  int iterations = 0;
};

// Refines `init` (T_cam_model) by aligning `model` (points in the model
// frame, with normals) to `scene` (camera frame, with normals). method is
// one of: none icp icp_lm icp_plane gicp ndt (InputError otherwise). Random
// choices draw from `seed`.
RefineResult refine_pose(const std::string& method, const PointSet& model, const PointSet& scene,
                         const Pose& init, const RefineSettings& s, uint64_t seed);

}  // namespace pb
