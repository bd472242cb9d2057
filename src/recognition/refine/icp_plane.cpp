// ICP point-to-plane (pcl::IterativeClosestPointWithNormals: linear least
// squares on the distances of source points to the tangent planes of their
// nearest target points, TransformationEstimationPointToPlaneLLS). Normals
// come from the clouds (refine_pose estimates them when absent). Frame and
// units: refine_internal.h.
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <cmath>

#include "recognition/refine/internal.h"

namespace pb {
namespace refine_detail {

namespace {

class IcpPlane : public pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> {
 public:
  int iterations() const { return nr_iterations_; }
};

pcl::PointCloud<pcl::PointNormal>::Ptr to_cloud(const std::vector<Vec3f>& pts, const std::vector<Vec3f>& nrm) {
  pcl::PointCloud<pcl::PointNormal>::Ptr c(new pcl::PointCloud<pcl::PointNormal>);
  c->resize(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    (*c)[i].getVector3fMap() = pts[i];
    (*c)[i].getNormalVector3fMap() = nrm[i];
    (*c)[i].curvature = 0;
  }
  return c;
}

}  // namespace

Outcome run_icp_plane(const Problem& p, const RefineSettings& s) {
  auto src = to_cloud(p.src, p.src_normals);
  auto tgt = to_cloud(p.tgt, p.tgt_normals);
  pcl::PointCloud<pcl::PointNormal> out;

  IcpPlane icp;
  icp.setInputSource(src);
  icp.setInputTarget(tgt);
  icp.setMaximumIterations(s.max_iterations);
  icp.setMaxCorrespondenceDistance(s.max_correspondence_mm * 1e-3);
  icp.setTransformationEpsilon(s.transformation_epsilon);
  icp.setTransformationRotationEpsilon(std::cos(s.rotation_epsilon_deg * M_PI / 180.0));
  icp.setEuclideanFitnessEpsilon(s.fitness_epsilon);
  icp.setUseReciprocalCorrespondences(s.reciprocal_correspondences);
  icp.align(out);

  Outcome o;
  o.delta = icp.getFinalTransformation();
  o.iterations = icp.iterations();
  using CC = pcl::registration::DefaultConvergenceCriteria<float>;
  const auto state = icp.getConvergeCriteria()->getConvergenceState();
  o.converged = state == CC::CONVERGENCE_CRITERIA_TRANSFORM || state == CC::CONVERGENCE_CRITERIA_ABS_MSE ||
                state == CC::CONVERGENCE_CRITERIA_REL_MSE;
  return o;
}

}  // namespace refine_detail
}  // namespace pb
