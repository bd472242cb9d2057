// Private to the refine_*.cpp files: the registration problem as every PCL
// method sees it. PCL-free (each method converts inside its own .cpp, so the
// heavy PCL templates are compiled once per method, in parallel-friendly
// units).
//
// Frame and units: refine_pose (refine_pose.cpp) crops the scene to the
// neighbourhood of the model at its initial pose, subtracts the crop's
// centroid c (mm) and converts to metres. The source (model) points are
// already mapped by the initial pose into that frame, so every method starts
// from the identity and returns the correction `delta` (metres, local frame):
//   x_cam = c + 1000 * delta((T_init(x_model) - c) / 1000).
// PCL's defaults (NDT, GICP) are tuned for metres; float keeps 7 digits,
// i.e. micrometres for clouds within a metre of the origin.
#pragma once

#include <cstdint>
#include <vector>

#include "core/types.h"
#include "recognition/refine/refine.h"

namespace pb {

class KdTree3;

namespace refine_detail {

// The leaf size of the crop's kd-tree (the own ICP's nearest-neighbour
// searches and the fitness).
constexpr int kTargetLeafSize = 24;

struct Problem {
  std::vector<Vec3f> src;          // model points, local frame (m), after the initial pose
  std::vector<Vec3f> src_normals;  // unit; filled when the method needs normals
  std::vector<Vec3f> tgt;          // cropped scene points, local frame (m)
  std::vector<Vec3f> tgt_normals;  // unit; filled when the method needs normals
  double model_diameter_m = 0;     // extent of the model cloud: its bounding box diagonal in the model frame
  const KdTree3* tgt_tree = nullptr;  // over tgt (leaf kTargetLeafSize), built once by refine_pose for
                                      // the method and the fitness; null: a method builds its own
};

struct Outcome {
  Eigen::Matrix4f delta = Eigen::Matrix4f::Identity();  // correction in the local frame (m)
  bool converged = false;  // stopped by a stopping rule before the iteration cap
  int iterations = 0;
};

// The methods the registry lists (registry.cpp); each is its PCL object and
// a configure function around the one driver in pcl_registration.h.
Outcome run_icp(const Problem& p, const RefineSettings& s, uint64_t seed);        // own (icp.cpp)
Outcome run_icp_plane(const Problem& p, const RefineSettings& s, uint64_t seed);  // own (icp.cpp)
Outcome run_icp_pcl(const Problem& p, const RefineSettings& s, uint64_t seed);    // stock PCL (icp_pcl.cpp)
Outcome run_icp_plane_pcl(const Problem& p, const RefineSettings& s, uint64_t seed);
Outcome run_icp_lm(const Problem& p, const RefineSettings& s, uint64_t seed);
Outcome run_gicp(const Problem& p, const RefineSettings& s, uint64_t seed);
Outcome run_ndt(const Problem& p, const RefineSettings& s, uint64_t seed);

// Unit normals by PCA over the k nearest neighbours (sign arbitrary: the
// point-to-plane and plane-to-plane metrics do not depend on it).
std::vector<Vec3f> estimate_normals(const std::vector<Vec3f>& pts, int k);

}  // namespace refine_detail
}  // namespace pb
