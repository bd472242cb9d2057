// ICP with Levenberg-Marquardt (pcl::IterativeClosestPointNonLinear: the
// point-to-point error minimised by LM over a 6-DoF warp instead of the
// closed-form SVD). Frame and units: internal.h.
#include <pcl/registration/icp_nl.h>

#include "recognition/pcl_adapter.h"
#include "recognition/refine/pcl_registration.h"

namespace pb::refine_detail {

Outcome run_icp_lm(const Problem& p, const RefineSettings& s, uint64_t /*seed*/) {
  Counted<pcl::IterativeClosestPointNonLinear<pcl::PointXYZ, pcl::PointXYZ>> icp;
  return align<StopReport::kCriteria>(icp, pcl_adapter::xyz(p.src), pcl_adapter::xyz(p.tgt), s,
               [&](auto& r) { configure_icp_family(r, s); }, no_after_inputs());
}

}  // namespace pb::refine_detail
