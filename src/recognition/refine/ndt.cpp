// 3D-NDT (pcl::NormalDistributionsTransform: Newton's method with a
// More-Thuente line search on a grid of normal distributions built from the
// scene). Grid sized to the object (PCL_NOTES: for a 15 cm object only a
// 2 cm grid converged). PCL compares its transformation epsilon with the
// squared translation step (m^2), so the ICP family's epsilon is used as is;
// its hasConverged() is also true at the iteration cap, so convergence here
// means "stopped before the cap". Frame and units: refine_internal.h.
#include <pcl/point_types.h>
#include <pcl/registration/ndt.h>

#include <algorithm>
#include <cmath>

#include "recognition/refine/internal.h"

namespace pb {
namespace refine_detail {

namespace {

class Ndt : public pcl::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> {
 public:
  int iterations() const { return nr_iterations_; }
};

}  // namespace

Outcome run_ndt(const Problem& p, const RefineSettings& s) {
  using Cloud = pcl::PointCloud<pcl::PointXYZ>;
  Cloud::Ptr src(new Cloud), tgt(new Cloud), out(new Cloud);
  src->resize(p.src.size());
  for (size_t i = 0; i < p.src.size(); ++i) (*src)[i].getVector3fMap() = p.src[i];
  tgt->resize(p.tgt.size());
  for (size_t i = 0; i < p.tgt.size(); ++i) (*tgt)[i].getVector3fMap() = p.tgt[i];

  double res_m = s.ndt_resolution_mm * 1e-3;
  if (s.ndt_resolution_fraction > 0) res_m = std::max(res_m, s.ndt_resolution_fraction * p.model_diameter_m);

  Ndt ndt;
  ndt.setMinPointPerVoxel(static_cast<unsigned>(std::max(3, s.ndt_min_points_per_cell)));
  ndt.setResolution(static_cast<float>(res_m));
  ndt.setStepSize(s.ndt_step_size_mm * 1e-3);
  ndt.setOulierRatio(  // sic, PCL 1.13 spelling
      s.ndt_outlier_ratio);
  ndt.setMaximumIterations(s.max_iterations);
  ndt.setTransformationEpsilon(s.transformation_epsilon);
  ndt.setTransformationRotationEpsilon(std::cos(s.rotation_epsilon_deg * M_PI / 180.0));
  ndt.setInputSource(src);
  ndt.setInputTarget(tgt);
  ndt.align(*out);

  Outcome o;
  o.delta = ndt.getFinalTransformation();
  o.iterations = ndt.iterations();
  o.converged = o.iterations < s.max_iterations;
  return o;
}

}  // namespace refine_detail
}  // namespace pb
