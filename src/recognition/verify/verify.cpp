// Verification (thesis 3.1): inliers are model points whose nearest scene
// point lies within a threshold. PointIndex is the project's kd-tree (kdtree.h).
#include "recognition/verify/verify.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "recognition/kdtree.h"

namespace pb {

struct PointIndex::Impl {
  KdTree3 tree;
};

PointIndex::PointIndex(const std::vector<Vec3f>& points) : impl_(new Impl) {
  for (const auto& p : points)
    if (!p.allFinite()) throw std::invalid_argument("PointIndex: non-finite point");  // callers pass finite clouds
  // 24 points per leaf, as refinement's crop trees (refine/internal.h),
  // which are cut from this one (KdTree3::restricted) and keep its leaves:
  // searches of a warehouse crop cut from a tree of 8 per leaf were 10-20%
  // slower than those of a crop tree built (results/bench/README.md). The
  // answers do not depend on it.
  impl_->tree = KdTree3(points, 24);
}

PointIndex::~PointIndex() = default;

size_t PointIndex::size() const { return impl_->tree.size(); }

const KdTree3& PointIndex::tree() const { return impl_->tree; }

int PointIndex::nearest(const Vec3f& q, float* sq_dist, float max_sq_dist, int hint) const {
  return impl_->tree.nearest(q, sq_dist, max_sq_dist, hint);
}

int PointIndex::any_within(const Vec3f& q, float max_sq_dist, int hint) const {
  return impl_->tree.any_within(q, max_sq_dist, hint);
}

std::vector<int> PointIndex::radius(const Vec3f& q, float r) const {
  std::vector<int> out;
  impl_->tree.radius(q, r, out);
  return out;
}

int count_inliers(const std::vector<Vec3f>& model_points, const Pose& T_cam_model, const PointIndex& scene,
                  double threshold_mm) {
  if (scene.size() == 0) return 0;
  const Eigen::Matrix3d R = T_cam_model.R;
  const Vec3 t = T_cam_model.t;
  const float thr2 = static_cast<float>(threshold_mm * threshold_mm);
  // A point is an inlier when some scene point is within the threshold
  // (squared distance <= thr2 is below the next float up): the search ends
  // at the first one found, or early when there is none. The previous
  // point's match (model points are stored in scan order, neighbours mostly
  // adjacent) is tried first; neither changes which points count.
  const float bound = std::nextafter(thr2, std::numeric_limits<float>::infinity());
  int n = 0, hint = -1;
  for (const auto& p : model_points) {
    const Vec3f q = (R * p.cast<double>() + t).cast<float>();
    const int k = scene.any_within(q, bound, hint);
    if (k >= 0) {
      ++n;
      hint = k;
    }
  }
  return n;
}

DepthEvidence depth_evidence(const PointSet& model, const Pose& T_cam_model, const DepthImage& depth,
                             const Intrinsics& K, double tolerance_mm) {
  DepthEvidence e;
  if (!depth.fits(K)) throw std::invalid_argument("depth_evidence: depth image and intrinsics differ in size");
  const Eigen::Matrix3d R = T_cam_model.R;
  const Vec3 t = T_cam_model.t;
  const bool normals = model.has_normals();
  for (size_t i = 0; i < model.points.size(); ++i) {
    const Vec3 q = R * model.points[i].cast<double>() + t;
    if (!(q.z() > 0)) continue;
    if (normals && (R * model.normals[i].cast<double>()).dot(q) >= 0) continue;  // faces away
    const Eigen::Vector2d uv = K.project(q);
    // The nearest pixel centre; checked in floating point first, so that a
    // point far off the image never reaches an integer conversion.
    // (lround rounds halves away from zero: -0.5 -> -1, width - 0.5 -> width.)
    if (!(uv.x() > -0.5 && uv.x() < depth.width - 0.5 && uv.y() > -0.5 && uv.y() < depth.height - 0.5)) continue;
    const int col = static_cast<int>(std::lround(uv.x())), row = static_cast<int>(std::lround(uv.y()));
    const float z_obs = depth.at(col, row);
    if (!(z_obs > 0) || !std::isfinite(z_obs)) continue;
    const double d = static_cast<double>(z_obs) - q.z();
    if (d > tolerance_mm) ++e.violating;
    else if (d < -tolerance_mm) ++e.occluded;
    else ++e.supported;
  }
  return e;
}

OutlineEvidence outline_evidence(const PointSet& model, const Pose& T_cam_model, const DepthImage& depth,
                                 const Intrinsics& K, double spacing_mm, double tolerance_mm, int gap_px) {
  OutlineEvidence e;
  if (!depth.fits(K)) throw std::invalid_argument("outline_evidence: depth image and intrinsics differ in size");
  const Eigen::Matrix3d R = T_cam_model.R;
  const Vec3 t = T_cam_model.t;
  const bool normals = model.has_normals();
  // The facing points in the image: pixel, half the square's side, depth.
  struct Splat {
    int u, v, half;
    float z;
  };
  std::vector<Splat> splats;
  int u0 = depth.width, v0 = depth.height, u1 = -1, v1 = -1;
  for (size_t i = 0; i < model.points.size(); ++i) {
    const Vec3 q = R * model.points[i].cast<double>() + t;
    if (!(q.z() > 0)) continue;
    if (normals && (R * model.normals[i].cast<double>()).dot(q) >= 0) continue;
    const Eigen::Vector2d uv = K.project(q);
    if (!(uv.x() > -0.5 && uv.x() < depth.width - 0.5 && uv.y() > -0.5 && uv.y() < depth.height - 0.5)) continue;
    // Squares 1.5 point spacings wide, so that neighbouring points' squares
    // overlap and the mask has no holes; at least 3 px (an unvoxelized
    // cloud, spacing 0), at most 33.
    const int half = static_cast<int>(std::clamp(std::ceil(0.75 * spacing_mm * K.fx / q.z()), 1.0, 16.0));
    const Splat s{static_cast<int>(std::lround(uv.x())), static_cast<int>(std::lround(uv.y())), half,
                  static_cast<float>(q.z())};
    u0 = std::min(u0, s.u - half);
    v0 = std::min(v0, s.v - half);
    u1 = std::max(u1, s.u + half);
    v1 = std::max(v1, s.v + half);
    splats.push_back(s);
  }
  if (splats.empty()) return e;
  // The mask's raster: its box and gap_px around it (for the probes), clipped to the image.
  const int g = std::max(1, gap_px);
  u0 = std::max(0, u0 - g);
  v0 = std::max(0, v0 - g);
  u1 = std::min(depth.width - 1, u1 + g);
  v1 = std::min(depth.height - 1, v1 + g);
  const int w = u1 - u0 + 1, h = v1 - v0 + 1;
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> zbuf(static_cast<size_t>(w) * h, inf);
  auto at = [&](int u, int v) -> float& { return zbuf[static_cast<size_t>(v - v0) * w + (u - u0)]; };
  for (const Splat& s : splats)
    for (int v = std::max(v0, s.v - s.half); v <= std::min(v1, s.v + s.half); ++v)
      for (int u = std::max(u0, s.u - s.half); u <= std::min(u1, s.u + s.half); ++u) at(u, v) = std::min(at(u, v), s.z);
  auto inside = [&](int u, int v) { return u >= u0 && u <= u1 && v >= v0 && v <= v1 && at(u, v) < inf; };
  static const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
  for (int v = v0; v <= v1; ++v)
    for (int u = u0; u <= u1; ++u) {
      if (!(at(u, v) < inf)) continue;
      // Outward: toward the 4-neighbours outside the mask.
      int ou = 0, ov = 0;
      for (int k = 0; k < 4; ++k)
        if (!inside(u + du[k], v + dv[k])) {
          ou += du[k];
          ov += dv[k];
        }
      if (ou == 0 && ov == 0) continue;  // interior (or a one-pixel sliver)
      const double n = std::hypot(ou, ov);
      const int pu = static_cast<int>(std::lround(u + g * ou / n)), pv = static_cast<int>(std::lround(v + g * ov / n));
      if (pu < 0 || pv < 0 || pu >= depth.width || pv >= depth.height || inside(pu, pv)) continue;
      const float z_obs = depth.at(pu, pv);
      if (!(z_obs > 0) || !std::isfinite(z_obs)) continue;
      ++e.probed;
      const double step = static_cast<double>(z_obs) - at(u, v);
      if (std::abs(step) <= tolerance_mm) ++e.continuous;
      else if (step < 0) ++e.nearer;
    }
  return e;
}

double visibility_score(const PointSet& model, const Pose& T_cam_model, const DepthImage& depth, const Intrinsics& K,
                        const VerifySettings& v, double spacing_mm) {
  const double evidence = depth_evidence(model, T_cam_model, depth, K, v.inlier_threshold_mm).score(v.violation_weight);
  if (!(v.outline_weight > 0) || !(evidence > 0)) return evidence;
  const OutlineEvidence o =
      outline_evidence(model, T_cam_model, depth, K, spacing_mm, v.inlier_threshold_mm, v.outline_gap_px);
  return evidence * (1.0 - v.outline_weight + v.outline_weight * o.standing_fraction());
}

}  // namespace pb
