// OUR-CVFH signatures with their semi-global unique reference frames, through
// pcl::OURCVFHEstimation. PCL's implementation hard-codes a 1 cm sigma for its
// octant weights, so the cloud is passed in metres and the frames converted
// back to millimetres.
#include <pcl/features/our_cvfh.h>

#include <algorithm>
#include <cmath>

#include "recognition/global/internal.h"
#include "recognition/global/pcl_cvfh.h"

namespace pb::global {

namespace {

constexpr float kToM = 0.001f;

// Guard (PCL issues 1449, 1491): OUR-CVFH keeps, of each stable region,
// the points whose normal is within refine_clusters x eps of the region's
// mean normal; when that leaves very few points (1 or 2, or points all
// equally far from their centroid) its frame is NaN and PCL indexes out of
// bounds (reproduced: tests/test_recognition_global_method.cpp).
// The same regions are found here first (same algorithm, same metre-scaled
// input); if one would be degenerate, every region point is kept instead.
float safe_refine_clusters(const PclInput& in, const GlobalSettings& s) {
  const auto& pts = *in.points;
  const auto& nrm = *in.normals;
  float refine = static_cast<float>(s.ourcvfh_refine_clusters);
  PointSet scaled;
  for (size_t i = 0; i < pts.size(); ++i) {
    scaled.points.push_back(pts[i].getVector3fMap());
    scaled.normals.push_back(nrm[i].getNormalVector3fMap());
    scaled.curvature.push_back(nrm[i].curvature);
  }
  GlobalSettings gm = s;
  gm.cvfh_cluster_tolerance_mm = s.cvfh_cluster_tolerance_mm * kToM;
  gm.cvfh_normal_radius_mm = s.cvfh_normal_radius_mm * kToM;
  const double eps = s.cvfh_eps_angle_deg * M_PI / 180.0;
  for (const Region& r : stable_regions(scaled, gm)) {
    std::vector<Vec3f> kept;
    for (size_t k = 0; k < r.points.size(); ++k) {
      const double dot = std::clamp(static_cast<double>(r.mean_normal.dot(r.normals[k])), -1.0, 1.0);
      if (std::abs(std::acos(dot)) < eps * refine) kept.push_back(r.points[k]);
    }
    // Fewer than 5 (not 3): a margin for points at the angle threshold,
    // where float sums may round differently from PCL's.
    bool degenerate = kept.size() < 5;
    if (!degenerate) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const auto& p : kept) c += p.cast<double>();
      c /= static_cast<double>(kept.size());
      double dmin = 1e30, dmax = 0;
      for (const auto& p : kept) {
        const double d = (p.cast<double>() - c).norm();
        dmin = std::min(dmin, d);
        dmax = std::max(dmax, d);
      }
      degenerate = !(dmax - dmin > 1e-6);
    }
    if (degenerate) {
      refine = static_cast<float>(M_PI / eps) + 1.f;  // every region point passes
      break;
    }
  }
  return refine;
}

// The signatures, regions and frames PCL computed, in millimetres.
std::vector<Signature> read_signatures(pcl::OURCVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308>& est,
                                       const pcl::PointCloud<pcl::VFHSignature308>& sigs) {
  std::vector<Signature> out;
  std::vector<Eigen::Vector3f, Eigen::aligned_allocator<Eigen::Vector3f>> centroids, normals;
  est.getCentroidClusters(centroids);
  est.getCentroidNormalClusters(normals);
  std::vector<Eigen::Matrix4f, Eigen::aligned_allocator<Eigen::Matrix4f>> transforms;
  est.getTransforms(transforms);
  std::vector<bool> valid;
  est.getValidTransformsVec(valid);
  std::vector<short> axes_per_cluster;
  est.getClusterAxes(axes_per_cluster);

  // Signature k belongs to the region whose frames it enumerates (issue 737:
  // a region can have 1, 2 or 4 frames).
  std::vector<int> region_of;
  if (!normals.empty()) {
    for (size_t r = 0; r < axes_per_cluster.size(); ++r)
      for (int a = 0; a < axes_per_cluster[r]; ++a) region_of.push_back(static_cast<int>(r));
  }
  for (size_t k = 0; k < sigs.size(); ++k) {
    Signature sig;
    sig.hist.assign(sigs[k].histogram, sigs[k].histogram + 308);
    bool finite = true;
    for (float v : sig.hist) finite = finite && std::isfinite(v);
    if (!finite) continue;
    const int r = k < region_of.size() ? region_of[k] : -1;
    if (r >= 0 && static_cast<size_t>(r) < centroids.size() && static_cast<size_t>(r) < normals.size()) {
      sig.centroid = centroids[r] / kToM;
      if (normals[r].allFinite() && normals[r].norm() > 0.5f) {
        sig.axis = -normals[r].normalized();
        sig.from_normal = true;
      } else {
        sig.axis = sig.centroid.normalized();
      }
    } else if (!centroids.empty()) {
      sig.centroid = centroids.front() / kToM;
      sig.axis = sig.centroid.normalized();
    } else {
      continue;
    }
    if (k < transforms.size() && k < valid.size() && valid[k] && transforms[k].allFinite()) {
      Mat4 T = transforms[k].cast<double>();
      T.block<3, 1>(0, 3) /= kToM;
      Pose P = Pose::from_matrix(T);
      // PCL builds the frame as (x, x cross z, z): a reflection (det -1).
      // Keep it as is (orthonormalized, sign kept): the composition of a
      // scene frame with a view frame is a proper rotation again.
      Eigen::JacobiSVD<Mat3> svd(P.R, Eigen::ComputeFullU | Eigen::ComputeFullV);
      P.R = svd.matrixU() * svd.matrixV().transpose();
      sig.T_rf_cam = P;
      sig.has_rf = true;
    }
    out.push_back(std::move(sig));
  }
  return out;
}

}  // namespace

std::vector<Signature> ourcvfh_signatures(const PointSet& cloud, const GlobalSettings& s) {
  if (!cloud.has_normals()) return {};
  const PclInput in = pcl_input(cloud, kToM, true);
  // Guard (PCL issues 1449, 1491): too few points for a region and its frame.
  if (in.points->size() < static_cast<size_t>(std::max(s.cvfh_min_region_points, 10))) return {};
  pcl::OURCVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308> est;
  configure_cvfh_family(est, in, s, kToM);
  est.setAxisRatio(static_cast<float>(s.ourcvfh_axis_ratio));
  est.setMinAxisValue(static_cast<float>(s.ourcvfh_min_axis_value));
  est.setRefineClusters(safe_refine_clusters(in, s));
  pcl::PointCloud<pcl::VFHSignature308> sigs;
  est.compute(sigs);
  return read_signatures(est, sigs);
}

}  // namespace pb::global
