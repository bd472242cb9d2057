// ICP point-to-point (pcl::IterativeClosestPoint, SVD per iteration), on an
// optional random subset of the source points (thesis: "random subset of
// source points"), drawn from pb::Rng. Frame and units: refine_internal.h.
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/random.h"
#include "recognition/refine/internal.h"

namespace pb {
namespace refine_detail {

namespace {

// Exposes the iteration count (protected in PCL).
class Icp : public pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> {
 public:
  int iterations() const { return nr_iterations_; }
};

}  // namespace

Outcome run_icp(const Problem& p, const RefineSettings& s, uint64_t seed) {
  using Cloud = pcl::PointCloud<pcl::PointXYZ>;
  // Source subset: the first k of a seeded Fisher-Yates shuffle, in index order.
  std::vector<size_t> idx(p.src.size());
  std::iota(idx.begin(), idx.end(), size_t(0));
  if (s.icp_sample_points > 0 && static_cast<size_t>(s.icp_sample_points) < idx.size()) {
    Rng rng(seed);
    const size_t k = static_cast<size_t>(s.icp_sample_points);
    for (size_t i = 0; i < k; ++i) {
      const size_t j = i + static_cast<size_t>(rng.uniform_int(0, static_cast<int>(idx.size() - i - 1)));
      std::swap(idx[i], idx[j]);
    }
    idx.resize(k);
    std::sort(idx.begin(), idx.end());
  }
  Cloud::Ptr src(new Cloud), tgt(new Cloud), out(new Cloud);
  src->resize(idx.size());
  for (size_t i = 0; i < idx.size(); ++i) (*src)[i].getVector3fMap() = p.src[idx[i]];
  tgt->resize(p.tgt.size());
  for (size_t i = 0; i < p.tgt.size(); ++i) (*tgt)[i].getVector3fMap() = p.tgt[i];

  Icp icp;
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
