// ICP point-to-plane (pcl::IterativeClosestPointWithNormals: linear least
// squares on the distances of source points to the tangent planes of their
// nearest target points, TransformationEstimationPointToPlaneLLS). Normals
// come from the clouds (refine_pose estimates them when absent). Frame and
// units: internal.h.
#include <pcl/registration/icp.h>

#include "recognition/pcl_adapter.h"
#include "recognition/refine/pcl_registration.h"

namespace pb::refine_detail {

Outcome run_icp_plane(const Problem& p, const RefineSettings& s, uint64_t /*seed*/) {
  Counted<pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal>> icp;
  return align<StopReport::kCriteria>(icp, pcl_adapter::point_normals(p.src, p.src_normals), pcl_adapter::point_normals(p.tgt, p.tgt_normals),
               s, [&](auto& r) { configure_icp_family(r, s); }, no_after_inputs());
}

}  // namespace pb::refine_detail
