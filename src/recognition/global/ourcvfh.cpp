// OUR-CVFH signatures with their semi-global unique reference frames: the
// stable regions (regions.cpp) and VFH (cvfh.cpp) are the project's, the
// frames and octant shape distribution pcl::OURCVFHEstimation's
// (computeRFAndShapeDistribution, given the regions). PCL's implementation
// hard-codes a 1 cm sigma for its octant weights, so the cloud is passed in
// metres and the frames converted back to millimetres.
#include <pcl/features/our_cvfh.h>

#include <algorithm>
#include <cmath>

#include "recognition/global/internal.h"
#include "recognition/global/pcl_cvfh.h"

namespace pb::global {

namespace {

constexpr float kToM = 0.001f;

// OUR-CVFH's regions: of each stable region (regions.cpp), the points whose
// recomputed normal lies within refine_clusters x eps of the region's mean
// normal (PCL: float sums, the arccos compared; a dot product rounded above
// 1, whose arccos is NaN in PCL, passes here), with the mean normal and
// centroid of those points (float sums in index order, as PCL), empty
// regions dropped.
// Guard (PCL issues 1449, 1491): when a region keeps very few points (1 or
// 2, or points all equally far from their centroid) PCL's frame is NaN and
// it indexes out of bounds (reproduced: tests/test_recognition_global_method
// .cpp); then every region keeps all its points (fewer than 5, not 3: a
// margin kept from when this guard predicted PCL's own regions).
struct OurRegion {
  pcl::PointIndices indices;  // into the input cloud
  Eigen::Vector3f centroid, normal;
};

std::vector<OurRegion> our_regions(const PointSet& scaled, const GlobalSettings& gm, double eps, double refine) {
  const std::vector<Region> regions = stable_regions(scaled, gm);
  const auto mean_of = [](const Region& r, const std::vector<size_t>& kept, Eigen::Vector3f& c, Eigen::Vector3f& n) {
    c.setZero();
    n.setZero();
    for (const size_t k : kept) {
      c += r.points[k];
      n += r.normals[k];
    }
    c /= static_cast<float>(kept.size());
    n /= static_cast<float>(kept.size());
    n.normalize();
  };
  for (const bool all : {false, true}) {
    std::vector<OurRegion> out;
    bool degenerate = false;
    for (const Region& r : regions) {
      std::vector<size_t> every(r.points.size()), kept;
      for (size_t k = 0; k < every.size(); ++k) every[k] = k;
      Eigen::Vector3f c, n;
      mean_of(r, every, c, n);
      for (size_t k = 0; k < r.points.size(); ++k) {
        const double dot = std::clamp(static_cast<double>(n.dot(r.normals[k])), -1.0, 1.0);
        if (all || std::acos(dot) < eps * refine) kept.push_back(k);
      }
      if (kept.empty()) continue;
      bool few = kept.size() < 5;
      if (!few) {
        Eigen::Vector3d m = Eigen::Vector3d::Zero();
        for (const size_t k : kept) m += r.points[k].cast<double>();
        m /= static_cast<double>(kept.size());
        double dmin = 1e30, dmax = 0;
        for (const size_t k : kept) {
          const double d = (r.points[k].cast<double>() - m).norm();
          dmin = std::min(dmin, d);
          dmax = std::max(dmax, d);
        }
        few = !(dmax - dmin > 1e-6);
      }
      degenerate = degenerate || few;
      OurRegion o;
      for (const size_t k : kept) o.indices.indices.push_back(r.indices[k]);
      mean_of(r, kept, o.centroid, o.normal);
      out.push_back(std::move(o));
    }
    if (!degenerate || all) return out;
  }
  return {};
}

// pcl::OURCVFHEstimation given the regions: its VFH per region (no distance
// component, as OUR-CVFH configures it) from the region's centroid and mean
// normal, then PCL's own semi-global frames and octant shape distribution
// (computeRFAndShapeDistribution), which fill the frames and the getters.
class GivenRegions : public pcl::OURCVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308> {
 public:
  void describe(const PclInput& in, const PointSet& scaled, std::vector<OurRegion> regions, bool normalize_bins,
                pcl::PointCloud<pcl::VFHSignature308>& output) {
    output.clear();
    for (OurRegion& r : regions) {
      const std::vector<float> h = vfh_histogram(scaled.points, scaled.normals, r.centroid, r.normal, normalize_bins,
                                                 false);
      pcl::VFHSignature308 sig;
      std::copy(h.begin(), h.end(), sig.histogram);
      output.push_back(sig);
      centroids_dominant_orientations_.push_back(r.centroid);
      dominant_normals_.push_back(r.normal);
      clusters_.push_back(std::move(r.indices));
    }
    pcl::PointCloud<pcl::PointXYZ>::Ptr processed(new pcl::PointCloud<pcl::PointXYZ>(*in.points));
    computeRFAndShapeDistribution(processed, output, clusters_);
  }
};

// The CVFH family's settings (in metres) and OUR-CVFH's axis rules.
void configure_ourcvfh(pcl::OURCVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308>& est,
                       const PclInput& in, const GlobalSettings& s) {
  configure_cvfh_family(est, in, s, kToM);
  est.setAxisRatio(static_cast<float>(s.ourcvfh_axis_ratio));
  est.setMinAxisValue(static_cast<float>(s.ourcvfh_min_axis_value));
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
  PointSet scaled;
  for (size_t i = 0; i < in.points->size(); ++i) {
    scaled.points.push_back((*in.points)[i].getVector3fMap());
    scaled.normals.push_back((*in.normals)[i].getNormalVector3fMap());
    scaled.curvature.push_back((*in.normals)[i].curvature);
  }
  GlobalSettings gm = s;
  gm.cvfh_cluster_tolerance_mm = s.cvfh_cluster_tolerance_mm * kToM;
  gm.cvfh_normal_radius_mm = s.cvfh_normal_radius_mm * kToM;
  const double eps = s.cvfh_eps_angle_deg * M_PI / 180.0;
  const double refine = s.ourcvfh_refine_clusters > 0 ? s.ourcvfh_refine_clusters : 1.0;  // PCL: <= 0 means 1
  std::vector<OurRegion> regions = our_regions(scaled, gm, eps, refine);
  pcl::PointCloud<pcl::VFHSignature308> sigs;
  if (regions.empty()) {
    // No region: PCL's OUR-CVFH falls back to the VFH of all the points
    // (no frame, centroid only).
    pcl::OURCVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308> est;
    configure_ourcvfh(est, in, s);
    est.setRefineClusters(static_cast<float>(refine));
    est.compute(sigs);
    return read_signatures(est, sigs);
  }
  GivenRegions est;
  configure_ourcvfh(est, in, s);
  est.describe(in, scaled, std::move(regions), s.cvfh_normalize_bins, sigs);
  return read_signatures(est, sigs);
}

std::vector<Signature> ourcvfh_signatures_pcl(const PointSet& cloud, const GlobalSettings& s) {
  if (!cloud.has_normals()) return {};
  const PclInput in = pcl_input(cloud, kToM, true);
  pcl::OURCVFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::VFHSignature308> est;
  configure_ourcvfh(est, in, s);
  est.setRefineClusters(static_cast<float>(s.ourcvfh_refine_clusters));
  pcl::PointCloud<pcl::VFHSignature308> sigs;
  est.compute(sigs);
  return read_signatures(est, sigs);
}

}  // namespace pb::global
