// The refinement methods' interface: a Refiner aligns a source cloud (the
// model view at its initial pose) to a target (the cropped scene) and
// returns the correction. refine_pose (refine.h) sets the problem up and
// applies the result; the registry (registry.h) builds each method by name
// with the common RegistrationSettings and its own subsection. PCL-free:
// implementations convert inside their .cpp files.
//
// Frame and units: refine_pose crops the scene to the neighbourhood of the
// model at its initial pose, subtracts the crop's centroid c (mm) and
// converts to metres. The source points are already mapped by the initial
// pose into that frame, so every method starts from the identity and
// returns the correction `delta` (metres, local frame):
//   x_cam = c + 1000 * delta((T_init(x_model) - c) / 1000).
// PCL's defaults (NDT, GICP) are tuned for metres; float keeps 7 digits,
// i.e. micrometres for clouds within a metre of the origin.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/types.h"
#include "recognition/refine/refine.h"

namespace pb {

class KdTree3;

// What a refiner aligns (local frame, metres).
struct RegistrationProblem {
  std::vector<Vec3f> src;          // model points after the initial pose
  std::vector<Vec3f> src_normals;  // unit; filled when the refiner needs normals
  std::vector<Vec3f> tgt;          // cropped scene points
  std::vector<Vec3f> tgt_normals;  // unit; filled when the refiner needs normals
  double model_diameter_m = 0;     // extent of the model cloud: its bounding box diagonal in the model frame
  const KdTree3* tgt_tree = nullptr;  // over tgt (leaf kTargetLeafSize, refine/internal.h), built once by
                                      // refine_pose; null: a refiner builds its own
};

// What a refiner returns.
struct RegistrationOutcome {
  Eigen::Matrix4f delta = Eigen::Matrix4f::Identity();  // correction in the local frame (m)
  bool converged = false;  // stopped by a stopping rule before the iteration cap
  int iterations = 0;
};

class Refiner {
 public:
  virtual ~Refiner() = default;
  // Whether both clouds must carry normals (plane metrics, covariances from normals).
  virtual bool needs_normals() const = 0;
  // Aligns problem.src to problem.tgt from the identity. Const and
  // thread-safe; random choices draw from `seed`.
  virtual RegistrationOutcome align(const RegistrationProblem& problem, uint64_t seed) const = 0;
};

// The factories the registry (registry.cpp) lists; each gets the common
// settings and its own subsection alone.
std::unique_ptr<Refiner> make_icp_refiner(const RegistrationSettings& r, const IcpSettings& s);        // icp.cpp
std::unique_ptr<Refiner> make_icp_plane_refiner(const RegistrationSettings& r, const IcpSettings& s);  // icp.cpp
std::unique_ptr<Refiner> make_icp_pcl_refiner(const RegistrationSettings& r, const IcpSettings& s);    // stock PCL
std::unique_ptr<Refiner> make_icp_plane_pcl_refiner(const RegistrationSettings& r);                    // stock PCL
std::unique_ptr<Refiner> make_icp_lm_refiner(const RegistrationSettings& r);
std::unique_ptr<Refiner> make_gicp_refiner(const RegistrationSettings& r, const GicpSettings& s);
std::unique_ptr<Refiner> make_ndt_refiner(const RegistrationSettings& r, const NdtSettings& s);

}  // namespace pb
