// The registration driver every PCL refinement method plugs into (private
// to refine/*.cpp; includes PCL). A method is its PCL object plus a
// configure function: the driver sets the iteration cap, calls configure
// (before the inputs, so grids and neighbour settings are in place when PCL
// builds its target structures), sets source and target, calls after_inputs
// (for what PCL resets with the inputs, e.g. GICP's covariances), aligns from
// the identity and reads the correction, the iteration count and whether a
// stopping rule (not the cap) ended it. Frame and units: refiner.h.
#pragma once

#include <pcl/registration/default_convergence_criteria.h>
#include <pcl/registration/registration.h>

#include <cmath>
#include <type_traits>

#include "recognition/refine/internal.h"

namespace pb::refine_detail {

// Exposes PCL's protected iteration count.
template <typename Base>
class Counted : public Base {
 public:
  int iterations() const { return this->nr_iterations_; }
};

// How a method reports convergence.
enum class StopReport {
  kCriteria,     // the ICP family: PCL's convergence criteria state (transform or MSE rule fired)
  kBeforeCap,    // stopped before max_iterations (NDT: hasConverged() is true even at the cap)
  kFlagAndCap,   // hasConverged() and before the cap (GICP)
};

// cos of the rotation stopping threshold, as PCL's ICP family compares it.
inline double rotation_epsilon_cos(const RegistrationSettings& s) { return std::cos(s.rotation_epsilon_deg * M_PI / 180.0); }

template <StopReport report, typename Reg, typename CloudPtr, typename Configure, typename AfterInputs>
RegistrationOutcome pcl_align(Reg& reg, const CloudPtr& src, const CloudPtr& tgt, const RegistrationSettings& s,
                              Configure&& configure, AfterInputs&& after_inputs) {
  reg.setMaximumIterations(s.max_iterations);
  configure(reg);
  reg.setInputSource(src);
  reg.setInputTarget(tgt);
  after_inputs(reg);
  std::remove_const_t<typename CloudPtr::element_type> out;
  reg.align(out);

  RegistrationOutcome o;
  o.delta = reg.getFinalTransformation();
  o.iterations = reg.iterations();
  if constexpr (report == StopReport::kCriteria) {
    using CC = pcl::registration::DefaultConvergenceCriteria<float>;
    const auto state = reg.getConvergeCriteria()->getConvergenceState();
    o.converged = state == CC::CONVERGENCE_CRITERIA_TRANSFORM || state == CC::CONVERGENCE_CRITERIA_ABS_MSE ||
                  state == CC::CONVERGENCE_CRITERIA_REL_MSE;
  } else if constexpr (report == StopReport::kBeforeCap) {
    o.converged = o.iterations < s.max_iterations;
  } else {
    o.converged = reg.hasConverged() && o.iterations < s.max_iterations;
  }
  return o;
}

// The stopping and correspondence settings of the ICP family (icp, icp_lm,
// icp_plane): every pcl::IterativeClosestPoint subclass.
template <typename Icp>
void configure_icp_family(Icp& icp, const RegistrationSettings& s) {
  icp.setMaxCorrespondenceDistance(s.max_correspondence_mm * 1e-3);
  icp.setTransformationEpsilon(s.transformation_epsilon);
  icp.setTransformationRotationEpsilon(rotation_epsilon_cos(s));
  icp.setEuclideanFitnessEpsilon(s.fitness_epsilon);
  icp.setUseReciprocalCorrespondences(s.reciprocal_correspondences);
}

inline auto no_after_inputs() {
  return [](auto&) {};
}

}  // namespace pb::refine_detail
