// CVFH (Aldoma et al. 2011) PCL-free, as pcl::CVFHEstimation computes it
// (cvfh_pcl.cpp keeps PCL's as the reference): the stable regions
// (regions.cpp), then per region the VFH of the whole cloud (its points and
// normals as given) seen from the region's centroid and mean normal; no
// region: one VFH of the whole cloud from its centroid and the mean of its
// normals (not normalized, as PCL). The VFH follows
// pcl::VFHEstimation::computePointSPFHSignature and computeFeature bin by
// bin: f1, f2, f3 of the Darboux pair (centroid, normal) -> (point, normal)
// in 45 bins each, all three binned as angles over [-pi, pi] (PCL's; f2 and
// f3 are cosines, so only the middle bins fill), the distance to the
// centroid in 45 bins of the largest such distance, the angle of each normal
// to the direction from the centroid to the camera in 128 bins; a bin adds 1
// per point, or with normalize_bins 100 / (N - 1) (shape) and 100 / N
// (viewpoint). Differences from PCL, at rounding level: the pair features'
// (recognition/darboux.h), and the region's centroid and mean normal summed
// in double.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/atan2_bin.h"
#include "recognition/darboux.h"
#include "recognition/global/internal.h"

namespace pb::global {

namespace {

constexpr int kShapeBins = 45, kViewBins = 128, kVfhDim = 4 * kShapeBins + kViewBins;

}  // namespace

std::vector<float> vfh_histogram(const std::vector<Vec3f>& points, const std::vector<Vec3f>& normals,
                                 const Vec3f& centroid, const Vec3f& normal, bool normalize_bins,
                                 bool size_component) {
  std::vector<float> h(kVfhDim, 0.f);
  const size_t n = points.size();
  if (n == 0) return h;
  const double d_pi = static_cast<double>(1.0f / (2.0f * static_cast<float>(M_PI)));
  // The distance component's scale: the largest distance to the centroid
  // (pcl::getMaxDistance's, in float; only with the component).
  float max_dist = std::numeric_limits<float>::lowest();
  if (size_component)
    for (size_t i = 0; i < n; ++i) max_dist = std::max(max_dist, (centroid - points[i]).norm());
  const double dist_norm = static_cast<double>(max_dist);
  const float incr = normalize_bins ? 100.0f / static_cast<float>(n - 1) : 1.f;
  for (size_t i = 0; i < n; ++i) {
    float f1_y = 0, f1_x = 0, f2 = 0, f3 = 0, f4 = 0;
    bool symmetric = false;
    if (!darboux_pair(centroid, normal, points[i], normals[i], &f1_y, &f1_x, f2, f3, &symmetric, &f4)) continue;
    const auto angle_bin = [d_pi](float f) { return clamped_bin(kShapeBins * ((f + M_PI) * d_pi), kShapeBins); };
    h[static_cast<size_t>(binned_atan2(f1_y, f1_x, angle_bin))] += incr;
    h[static_cast<size_t>(kShapeBins + angle_bin(f2))] += incr;
    h[static_cast<size_t>(2 * kShapeBins + angle_bin(f3))] += incr;
    if (size_component)
      h[static_cast<size_t>(3 * kShapeBins + clamped_bin(kShapeBins * (f4 / dist_norm), kShapeBins))] += incr;
  }
  // The viewpoint component: the camera at the origin.
  const Vec3f to_camera = (-centroid).normalized();
  const float vp_incr = normalize_bins ? static_cast<float>(100.0 / static_cast<double>(n)) : 1.f;
  for (size_t i = 0; i < n; ++i) {
    const double alpha = (static_cast<double>(normals[i].dot(to_camera)) + 1.0) * 0.5;
    const double fi = std::floor(alpha * kViewBins);
    // PCL converts to size_t first: a negative value wraps and lands in the last bin.
    const int bin = fi < 0 ? kViewBins - 1 : static_cast<int>(std::min<double>(fi, kViewBins - 1));
    h[static_cast<size_t>(4 * kShapeBins + bin)] += vp_incr;
  }
  return h;
}

std::vector<Signature> cvfh_signatures(const PointSet& cloud, const GlobalSettings& s) {
  std::vector<Signature> out;
  if (!cloud.has_normals()) return out;
  // The points with finite coordinates and normals (as the PCL input).
  PointSet in;
  const bool has_c = cloud.curvature.size() == cloud.points.size();
  for (size_t i = 0; i < cloud.points.size(); ++i) {
    if (!cloud.points[i].allFinite() || !cloud.normals[i].allFinite()) continue;
    in.points.push_back(cloud.points[i]);
    in.normals.push_back(cloud.normals[i]);
    const float c = has_c ? cloud.curvature[i] : 0.f;
    in.curvature.push_back(std::isfinite(c) ? c : 0.f);
  }
  // VFH needs a few points to be meaningful.
  if (in.points.size() < 10) return out;
  const auto add = [&](std::vector<float> hist, const Vec3f& centroid, const Vec3f* axis_normal) {
    for (const float v : hist)
      if (!std::isfinite(v)) return;
    Signature sig;
    sig.hist = std::move(hist);
    sig.centroid = centroid;
    if (axis_normal && axis_normal->allFinite() && axis_normal->norm() > 0.5f) {
      sig.axis = -axis_normal->normalized();
      sig.from_normal = true;
    } else {
      sig.axis = centroid.normalized();
    }
    out.push_back(std::move(sig));
  };
  const std::vector<Region> regions = stable_regions(in, s);
  for (const Region& r : regions)
    add(vfh_histogram(in.points, in.normals, r.centroid, r.mean_normal, s.cvfh_normalize_bins), r.centroid,
        &r.mean_normal);
  if (regions.empty()) {
    // PCL's fallback: float sums in point order, the normals' mean as is.
    Vec3f c = Vec3f::Zero(), nsum = Vec3f::Zero();
    for (size_t i = 0; i < in.points.size(); ++i) {
      c += in.points[i];
      nsum += in.normals[i];
    }
    c /= static_cast<float>(in.points.size());
    nsum /= static_cast<float>(in.points.size());
    add(vfh_histogram(in.points, in.normals, c, nsum, s.cvfh_normalize_bins), c, nullptr);
  }
  return out;
}

}  // namespace pb::global
