// 3D-NDT (pcl::NormalDistributionsTransform: Newton's method with a
// More-Thuente line search on a grid of normal distributions built from the
// scene). Grid sized to the object (PCL_NOTES: for a 15 cm object only a
// 2 cm grid converged). PCL compares its transformation epsilon with the
// squared translation step (m^2), so the ICP family's epsilon is used as is;
// its hasConverged() is also true at the iteration cap, so convergence here
// means "stopped before the cap". Frame and units: internal.h.
#include <pcl/registration/ndt.h>

#include <algorithm>

#include "recognition/pcl_adapter.h"
#include "recognition/refine/pcl_registration.h"

namespace pb::refine_detail {

Outcome run_ndt(const Problem& p, const RefineSettings& s, uint64_t /*seed*/) {
  double res_m = s.ndt_resolution_mm * 1e-3;
  if (s.ndt_resolution_fraction > 0) res_m = std::max(res_m, s.ndt_resolution_fraction * p.model_diameter_m);
  Counted<pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ>> ndt;
  auto configure = [&](auto& r) {
    r.setMinPointPerVoxel(static_cast<unsigned>(std::max(3, s.ndt_min_points_per_cell)));
    r.setResolution(static_cast<float>(res_m));
    r.setStepSize(s.ndt_step_size_mm * 1e-3);
    r.setOulierRatio(s.ndt_outlier_ratio);  // sic, PCL 1.13 spelling
    r.setTransformationEpsilon(s.transformation_epsilon);
    r.setTransformationRotationEpsilon(rotation_epsilon_cos(s));
  };
  return align<StopReport::kBeforeCap>(ndt, pcl_adapter::xyz(p.src), pcl_adapter::xyz(p.tgt), s, configure,
               no_after_inputs());
}

}  // namespace pb::refine_detail
