// ICP with Levenberg-Marquardt (pcl::IterativeClosestPointNonLinear: the
// point-to-point error minimised by LM over a 6-DoF warp instead of the
// closed-form SVD). Frame and units: refine_internal.h.
#include <pcl/point_types.h>
#include <pcl/registration/icp_nl.h>

#include <cmath>

#include "recognition/refine/internal.h"

namespace pb {
namespace refine_detail {

namespace {

class IcpLm : public pcl::IterativeClosestPointNonLinear<pcl::PointXYZ, pcl::PointXYZ> {
 public:
  int iterations() const { return nr_iterations_; }
};

}  // namespace

Outcome run_icp_lm(const Problem& p, const RefineSettings& s) {
  using Cloud = pcl::PointCloud<pcl::PointXYZ>;
  Cloud::Ptr src(new Cloud), tgt(new Cloud), out(new Cloud);
  src->resize(p.src.size());
  for (size_t i = 0; i < p.src.size(); ++i) (*src)[i].getVector3fMap() = p.src[i];
  tgt->resize(p.tgt.size());
  for (size_t i = 0; i < p.tgt.size(); ++i) (*tgt)[i].getVector3fMap() = p.tgt[i];

  IcpLm icp;
  icp.setInputSource(src);
  icp.setInputTarget(tgt);
  icp.setMaximumIterations(s.max_iterations);
  icp.setMaxCorrespondenceDistance(s.max_correspondence_mm * 1e-3);
  icp.setTransformationEpsilon(s.transformation_epsilon);
  icp.setTransformationRotationEpsilon(std::cos(s.rotation_epsilon_deg * M_PI / 180.0));
  icp.setEuclideanFitnessEpsilon(s.fitness_epsilon);
  icp.setUseReciprocalCorrespondences(s.reciprocal_correspondences);
  icp.align(*out);

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
