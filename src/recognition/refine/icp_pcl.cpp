// Stock PCL ICP, registered as icp_pcl and icp_plane_pcl beside the
// project's own icp and icp_plane (icp.cpp), for side-by-side comparison:
// pcl::IterativeClosestPoint (SVD per iteration) and
// pcl::IterativeClosestPointWithNormals (linear least squares on the
// point-to-plane distances), through the one registration driver, with the
// same correspondence and stopping settings. PCL rebuilds its search trees
// on every call and the reciprocal tree on every iteration. Frame and units:
// internal.h.
#include <pcl/registration/icp.h>

#include "core/random.h"
#include "recognition/pcl_adapter.h"
#include "recognition/refine/pcl_registration.h"

namespace pb::refine_detail {

Outcome run_icp_pcl(const Problem& p, const RefineSettings& s, uint64_t seed) {
  Counted<pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>> icp;
  const auto src = pcl_adapter::xyz(p.src, sample_indices(p.src.size(), s.icp_sample_points, seed));
  return align<StopReport::kCriteria>(icp, src, pcl_adapter::xyz(p.tgt), s,
               [&](auto& r) { configure_icp_family(r, s); }, no_after_inputs());
}

Outcome run_icp_plane_pcl(const Problem& p, const RefineSettings& s, uint64_t /*seed*/) {
  Counted<pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal>> icp;
  return align<StopReport::kCriteria>(icp, pcl_adapter::point_normals(p.src, p.src_normals),
                                      pcl_adapter::point_normals(p.tgt, p.tgt_normals), s,
                                      [&](auto& r) { configure_icp_family(r, s); }, no_after_inputs());
}

}  // namespace pb::refine_detail
