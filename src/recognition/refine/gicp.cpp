// Generalized ICP (pcl::GeneralizedIterativeClosestPoint, plane-to-plane):
// each point carries a covariance that is flat along its surface; by default
// built from the clouds' normals (thesis: "covariances from normals"),
// otherwise PCL computes them from k neighbours. The clouds arrive de-meaned
// (centred on the scene crop, refiner.h): PCL issue 6263, GICP fails
// on clouds far from the origin.
#include <pcl/registration/gicp.h>

#include <cmath>

#include "recognition/pcl_adapter.h"
#include "recognition/refine/internal.h"
#include "recognition/refine/pcl_registration.h"

namespace pb {

namespace {

using namespace refine_detail;
using Gicp = pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>;

// Covariance of a locally planar patch with unit normal n: variance 1 in the
// plane, eps along the normal (PCL's gicp_epsilon 0.001).
Gicp::MatricesVectorPtr plane_covariances(const std::vector<Vec3f>& normals) {
  constexpr double kEps = 1e-3;
  auto cov = std::make_shared<Gicp::MatricesVector>(normals.size());
  for (size_t i = 0; i < normals.size(); ++i) {
    const Eigen::Vector3d n = normals[i].cast<double>().normalized();
    (*cov)[i] = Eigen::Matrix3d::Identity() - (1.0 - kEps) * n * n.transpose();
  }
  return cov;
}

// Plane-to-plane registration; the covariances from the normals when
// covariances_from_normals and both clouds have them, else PCL's from k
// neighbours.
class GicpRefiner : public refine_detail::RefinerWith<GicpSettings> {
 public:
  using RefinerWith::RefinerWith;
  bool needs_normals() const override { return s_.covariances_from_normals; }

  RegistrationOutcome align(const RegistrationProblem& p, uint64_t /*seed: no random choice*/) const override {
    const int k = static_cast<int>(s_.correspondence_randomness);
    const bool from_normals = s_.covariances_from_normals && p.src_normals.size() == p.src.size() &&
                              p.tgt_normals.size() == p.tgt.size();
    // PCL's own covariances need k neighbours in both clouds.
    if (!from_normals && (static_cast<int>(p.src.size()) < k || static_cast<int>(p.tgt.size()) < k)) return {};

    auto configure = [&](auto& reg) {
      if (!from_normals) reg.setCorrespondenceRandomness(k);
      reg.setMaxCorrespondenceDistance(r_.max_correspondence_mm * 1e-3);
      // PCL's GICP stops when every translation entry of the per-iteration
      // change is below transformation_epsilon (m, not squared) and every
      // rotation entry below rotation_epsilon (~ radians): the same rule as
      // the ICP family.
      reg.setTransformationEpsilon(std::sqrt(r_.transformation_epsilon));
      reg.setRotationEpsilon(r_.rotation_epsilon_deg * M_PI / 180.0);
      // The inner BFGS stops when the gradient norms drop below these; PCL's
      // 1e-2 assumes metre-sized scenes and stops several degrees short on
      // objects of about 10 cm (measured: mean rotation error 3.2 degrees).
      reg.setTranslationGradientTolerance(1e-6);
      reg.setRotationGradientTolerance(1e-6);
    };
    // Setting the inputs resets the covariances: set them after.
    auto after_inputs = [&](auto& reg) {
      if (!from_normals) return;
      reg.setSourceCovariances(plane_covariances(p.src_normals));
      reg.setTargetCovariances(plane_covariances(p.tgt_normals));
    };
    Counted<Gicp> gicp;
    return pcl_align<StopReport::kFlagAndCap>(gicp, pcl_adapter::xyz(p.src), pcl_adapter::xyz(p.tgt), r_, configure,
                                              after_inputs);
  }
};

}  // namespace

std::unique_ptr<Refiner> make_gicp_refiner(const RegistrationSettings& r, const GicpSettings& s) {
  return std::make_unique<GicpRefiner>(r, s);
}

}  // namespace pb
