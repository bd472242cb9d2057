// Stock PCL ICP, registered as icp_pcl and icp_plane_pcl beside the
// project's own icp and icp_plane (icp.cpp), for side-by-side comparison:
// pcl::IterativeClosestPoint (SVD per iteration) and
// pcl::IterativeClosestPointWithNormals (linear least squares on the
// point-to-plane distances), through the one registration driver, with the
// same correspondence and stopping settings. PCL rebuilds its search trees
// on every call and the reciprocal tree on every iteration. Frame and units:
// refiner.h.
#include <pcl/registration/icp.h>

#include "core/random.h"
#include "recognition/pcl_adapter.h"
#include "recognition/refine/internal.h"
#include "recognition/refine/pcl_registration.h"

namespace pb {

namespace {

using namespace refine_detail;

// Point-to-point, on icp.sample_points of the source points (seeded).
class IcpPclRefiner : public refine_detail::RefinerWith<IcpSettings> {
 public:
  using RefinerWith::RefinerWith;
  bool needs_normals() const override { return false; }
  RegistrationOutcome align(const RegistrationProblem& p, uint64_t seed) const override {
    Counted<pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>> icp;
    const auto src = pcl_adapter::xyz(p.src, sample_indices(p.src.size(), s_.sample_points, seed));
    return pcl_align<StopReport::kCriteria>(icp, src, pcl_adapter::xyz(p.tgt), r_,
                                            [&](auto& reg) { configure_icp_family(reg, r_); }, no_after_inputs());
  }
};

// Point-to-plane, on every source point.
class IcpPlanePclRefiner : public Refiner {
 public:
  explicit IcpPlanePclRefiner(const RegistrationSettings& r) : r_(r) {}
  bool needs_normals() const override { return true; }
  RegistrationOutcome align(const RegistrationProblem& p, uint64_t /*seed: no random choice*/) const override {
    Counted<pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal>> icp;
    return pcl_align<StopReport::kCriteria>(icp, pcl_adapter::point_normals(p.src, p.src_normals),
                                            pcl_adapter::point_normals(p.tgt, p.tgt_normals), r_,
                                            [&](auto& reg) { configure_icp_family(reg, r_); }, no_after_inputs());
  }

 private:
  RegistrationSettings r_;
};

}  // namespace

std::unique_ptr<Refiner> make_icp_pcl_refiner(const RegistrationSettings& r, const IcpSettings& s) {
  return std::make_unique<IcpPclRefiner>(r, s);
}

std::unique_ptr<Refiner> make_icp_plane_pcl_refiner(const RegistrationSettings& r) {
  return std::make_unique<IcpPlanePclRefiner>(r);
}

}  // namespace pb
