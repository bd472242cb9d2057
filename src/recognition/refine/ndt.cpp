// 3D-NDT (pcl::NormalDistributionsTransform: Newton's method with a
// More-Thuente line search on a grid of normal distributions built from the
// scene). Grid sized to the object (PCL_NOTES: for a 15 cm object only a
// 2 cm grid converged). PCL compares its transformation epsilon with the
// squared translation step (m^2), so the ICP family's epsilon is used as is;
// its hasConverged() is also true at the iteration cap, so convergence here
// means "stopped before the cap". Frame and units: refiner.h.
#include <pcl/registration/ndt.h>

#include <algorithm>

#include "recognition/pcl_adapter.h"
#include "recognition/refine/internal.h"
#include "recognition/refine/pcl_registration.h"

namespace pb {

namespace {

class NdtRefiner : public refine_detail::RefinerWith<NdtSettings> {
 public:
  using RefinerWith::RefinerWith;
  bool needs_normals() const override { return false; }

  RegistrationOutcome align(const RegistrationProblem& p, uint64_t /*seed: no random choice*/) const override {
    using namespace refine_detail;
    double res_m = s_.resolution_mm * 1e-3;
    if (s_.resolution_fraction > 0) res_m = std::max(res_m, s_.resolution_fraction * p.model_diameter_m);
    Counted<pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ>> ndt;
    auto configure = [&](auto& reg) {
      reg.setMinPointPerVoxel(static_cast<unsigned>(std::max(3, s_.min_points_per_cell)));
      reg.setResolution(static_cast<float>(res_m));
      reg.setStepSize(s_.step_size_mm * 1e-3);
      reg.setOulierRatio(s_.outlier_ratio);  // sic, PCL 1.13 spelling
      reg.setTransformationEpsilon(r_.transformation_epsilon);
      reg.setTransformationRotationEpsilon(rotation_epsilon_cos(r_));
    };
    return pcl_align<StopReport::kBeforeCap>(ndt, pcl_adapter::xyz(p.src), pcl_adapter::xyz(p.tgt), r_, configure,
                                             no_after_inputs());
  }
};

}  // namespace

std::unique_ptr<Refiner> make_ndt_refiner(const RegistrationSettings& r, const NdtSettings& s) {
  return std::make_unique<NdtRefiner>(r, s);
}

}  // namespace pb
