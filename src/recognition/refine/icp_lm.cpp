// ICP with Levenberg-Marquardt (pcl::IterativeClosestPointNonLinear: the
// point-to-point error minimised by LM over a 6-DoF warp instead of the
// closed-form SVD). Frame and units: refiner.h.
#include <pcl/registration/icp_nl.h>

#include "recognition/pcl_adapter.h"
#include "recognition/refine/pcl_registration.h"

namespace pb {

namespace {

class IcpLmRefiner : public Refiner {
 public:
  explicit IcpLmRefiner(const RegistrationSettings& r) : r_(r) {}
  bool needs_normals() const override { return false; }
  RegistrationOutcome align(const RegistrationProblem& p, uint64_t /*seed: no random choice*/) const override {
    using namespace refine_detail;
    Counted<pcl::IterativeClosestPointNonLinear<pcl::PointXYZ, pcl::PointXYZ>> icp;
    return pcl_align<StopReport::kCriteria>(icp, pcl_adapter::xyz(p.src), pcl_adapter::xyz(p.tgt), r_,
                                            [&](auto& reg) { configure_icp_family(reg, r_); }, no_after_inputs());
  }

 private:
  RegistrationSettings r_;
};

}  // namespace

std::unique_ptr<Refiner> make_icp_lm_refiner(const RegistrationSettings& r) {
  return std::make_unique<IcpLmRefiner>(r);
}

}  // namespace pb
