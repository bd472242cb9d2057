#include "eval/bop_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "eval/bop_metrics_internal.h"
#include "render/renderer.h"

namespace pb {

using bop_detail::top_estimates;

namespace {

std::vector<double> arange_005_050() {
  // np.arange(0.05, 0.51, 0.05) evaluates start + i * step.
  std::vector<double> v;
  for (int i = 0; i < 10; ++i) v.push_back(0.05 + i * 0.05);
  return v;
}

const std::vector<Pose>& syms_or_identity(const std::vector<Pose>& s) {
  static const std::vector<Pose> kIdentity{Pose::identity()};
  return s.empty() ? kIdentity : s;
}

// Points as a 3 x N double matrix, ordered by decreasing distance from the
// origin: the far points usually hold the maximum, so the running maximum of a
// symmetry that cannot win passes the best one early and its loop stops.
Eigen::Matrix3Xd ordered_points(const std::vector<Vec3f>& points) {
  std::vector<size_t> order(points.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::vector<float> n2(points.size());
  for (size_t i = 0; i < points.size(); ++i) n2[i] = points[i].squaredNorm();
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return n2[a] > n2[b]; });
  Eigen::Matrix3Xd X(3, points.size());
  for (size_t i = 0; i < order.size(); ++i) X.col(i) = points[order[i]].cast<double>();
  return X;
}

// Visiting order of the symmetries: the one whose rotation is closest to the
// estimate's first (a tight bound early), then the rest by index.
std::vector<int> symmetry_order(const Pose& T_est, const Pose& T_gt, const std::vector<Pose>& syms) {
  std::vector<int> order(syms.size());
  std::iota(order.begin(), order.end(), 0);
  int first = 0;
  double best_tr = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < syms.size(); ++i) {
    const double tr = (T_est.R.transpose() * T_gt.R * syms[i].R).trace();
    if (tr > best_tr) {
      best_tr = tr;
      first = static_cast<int>(i);
    }
  }
  std::swap(order[0], order[first]);
  std::sort(order.begin() + 1, order.end());
  return order;
}

constexpr int kBlock = 256;

}  // namespace

std::vector<double> bop19_vsd_taus() { return arange_005_050(); }
std::vector<double> bop19_vsd_thresholds() { return arange_005_050(); }
std::vector<double> bop19_mssd_thresholds() { return arange_005_050(); }
std::vector<double> bop19_mspd_thresholds() {
  std::vector<double> v;
  for (int th = 5; th <= 50; th += 5) v.push_back(th);
  return v;
}

MssdResult mssd(const Pose& T_est, const Pose& T_gt, const std::vector<Vec3f>& points,
                const std::vector<Pose>& symmetries) {
  if (points.empty()) throw std::invalid_argument("mssd: the model has no points");
  const std::vector<Pose>& syms = syms_or_identity(symmetries);
  const Eigen::Matrix3Xd X = ordered_points(points);
  const Eigen::Index n = X.cols();

  double best2 = std::numeric_limits<double>::infinity();
  int best = -1;
  for (int s : symmetry_order(T_est, T_gt, syms)) {
    // T_e x - T_g S x = A x + b
    const Mat3 A = T_est.R - T_gt.R * syms[s].R;
    const Vec3 b = T_est.t - (T_gt.R * syms[s].t + T_gt.t);
    double max2 = 0;
    bool pruned = false;
    for (Eigen::Index c0 = 0; c0 < n; c0 += kBlock) {
      const Eigen::Index m = std::min<Eigen::Index>(kBlock, n - c0);
      const double blk = ((A * X.middleCols(c0, m)).colwise() + b).colwise().squaredNorm().maxCoeff();
      max2 = std::max(max2, blk);
      if (max2 > best2) {
        pruned = true;
        break;
      }
    }
    if (pruned) continue;
    if (max2 < best2 || (max2 == best2 && s < best)) {
      best2 = max2;
      best = s;
    }
  }
  MssdResult r;
  r.error_mm = std::sqrt(best2);
  r.symmetry = best < 0 ? 0 : best;
  return r;
}

MspdResult mspd(const Pose& T_est, const Pose& T_gt, const Intrinsics& K,
                const std::vector<Vec3f>& points, const std::vector<Pose>& symmetries) {
  if (points.empty()) throw std::invalid_argument("mspd: the model has no points");
  const std::vector<Pose>& syms = syms_or_identity(symmetries);
  const Eigen::Matrix3Xd X = ordered_points(points);
  const Eigen::Index n = X.cols();

  auto project = [&](const Eigen::Matrix3Xd& P) {
    Eigen::Matrix2Xd uv(2, P.cols());
    uv.row(0) = (K.fx * P.row(0).array() / P.row(2).array() + K.cx).matrix();
    uv.row(1) = (K.fy * P.row(1).array() / P.row(2).array() + K.cy).matrix();
    return uv;
  };
  const Eigen::Matrix2Xd uv_est = project((T_est.R * X).colwise() + T_est.t);

  double best2 = std::numeric_limits<double>::infinity();
  int best = -1;
  for (int s : symmetry_order(T_est, T_gt, syms)) {
    const Mat3 R = T_gt.R * syms[s].R;
    const Vec3 t = T_gt.R * syms[s].t + T_gt.t;
    double max2 = 0;
    bool pruned = false;
    for (Eigen::Index c0 = 0; c0 < n; c0 += kBlock) {
      const Eigen::Index m = std::min<Eigen::Index>(kBlock, n - c0);
      const Eigen::Matrix3Xd P = (R * X.middleCols(c0, m)).colwise() + t;
      const double blk = (project(P) - uv_est.middleCols(c0, m)).colwise().squaredNorm().maxCoeff();
      // NaN (a point on the camera plane) propagates as in numpy's max.
      if (std::isnan(blk)) {
        max2 = blk;
        break;
      }
      max2 = std::max(max2, blk);
      if (max2 > best2) {
        pruned = true;
        break;
      }
    }
    if (pruned || std::isnan(max2)) continue;
    if (max2 < best2 || (max2 == best2 && s < best)) {
      best2 = max2;
      best = s;
    }
  }
  MspdResult r;
  r.error_px = best < 0 ? std::numeric_limits<double>::infinity() : std::sqrt(best2);
  r.symmetry = best < 0 ? 0 : best;
  return r;
}

bool sphere_projections_overlap(double radius, const Vec3& p1, const Vec3& p2) {
  if (p1.z() == 0 || p2.z() == 0) return false;
  const Eigen::Vector2d q1(p1.x() / p1.z(), p1.y() / p1.z());
  const Eigen::Vector2d q2(p2.x() / p2.z(), p2.y() / p2.z());
  const double dist = (q1 - q2).norm();
  const double thresh = radius * (1.0 / p1.z() + 1.0 / p2.z());
  return dist < thresh;
}

namespace {

void check_size(const DepthImage& d, const Intrinsics& K, const char* what) {
  if (d.width != K.width || d.height != K.height ||
      d.z.size() != static_cast<size_t>(K.width) * K.height) {
    throw std::invalid_argument(std::string("vsd: the ") + what + " depth image is " +
                                std::to_string(d.width) + "x" + std::to_string(d.height) +
                                " but the intrinsics are " + std::to_string(K.width) + "x" +
                                std::to_string(K.height));
  }
}

}  // namespace

VsdResult vsd_from_renders(const DepthImage& depth_est, const DepthImage& depth_gt,
                           const DepthImage& scene_depth, const Intrinsics& K, double diameter,
                           const VsdOptions& opt) {
  check_size(depth_est, K, "estimate's");
  check_size(depth_gt, K, "ground truth's");
  check_size(scene_depth, K, "scene");
  if (opt.normalized_by_diameter && !(diameter > 0)) {
    throw std::invalid_argument("vsd: the diameter must be positive");
  }

  // Distances of the intersection pixels, and the mask counts.
  std::vector<double> dists;
  VsdResult r;
  const double delta = opt.delta_mm;
  for (int v = 0; v < K.height; ++v) {
    const double y = (v - K.cy) / K.fy;
    for (int u = 0; u < K.width; ++u) {
      const size_t i = static_cast<size_t>(v) * K.width + u;
      const double ze = depth_est.z[i], zg = depth_gt.z[i], zt = scene_depth.z[i];
      if (ze <= 0 && zg <= 0) continue;
      const double x = (u - K.cx) / K.fx;
      const double f = std::sqrt(x * x + y * y + 1.0);  // depth -> distance from the centre
      const double de = ze * f, dg = zg * f, dt = zt * f;
      // visibility.py computes the difference in float32.
      const bool test_missing = dt == 0;
      const bool vis_g = dg > 0 && (test_missing ||
                                    static_cast<float>(dg) - static_cast<float>(dt) <= delta);
      const bool vis_e = de > 0 && (test_missing || vis_g ||
                                    static_cast<float>(de) - static_cast<float>(dt) <= delta);
      r.visible_gt_px += vis_g;
      r.visible_est_px += vis_e;
      if (vis_g || vis_e) ++r.union_px;
      if (vis_g && vis_e) {
        ++r.intersection_px;
        double d = std::abs(dg - de);
        if (opt.normalized_by_diameter) d /= diameter;
        dists.push_back(d);
      }
    }
  }
  r.errors.assign(opt.taus.size(), 1.0);
  if (r.union_px == 0) return r;
  const long comp = r.union_px - r.intersection_px;
  for (size_t k = 0; k < opt.taus.size(); ++k) {
    long cost = 0;
    for (double d : dists) cost += (d >= opt.taus[k]);
    r.errors[k] = static_cast<double>(cost + comp) / static_cast<double>(r.union_px);
  }
  return r;
}

namespace {

DepthImage render_model(DepthRenderer& renderer, const Mesh& mesh, const Pose& T) {
  RenderItem item;
  item.mesh = &mesh;
  item.T_cam_model = T;
  item.label = 1;
  return renderer.render({item}).depth;
}

VsdResult vsd_shortcut_result(const VsdOptions& opt) {
  VsdResult r;
  r.errors.assign(opt.taus.size(), 1.0);
  r.shortcut = true;
  return r;
}

}  // namespace

VsdResult vsd(const Pose& T_est, const Pose& T_gt, const DepthImage& scene_depth, const Mesh& mesh,
              double diameter, DepthRenderer& renderer, const VsdOptions& opt) {
  if (opt.sphere_projection_shortcut &&
      !sphere_projections_overlap(0.5 * diameter, T_est.t, T_gt.t)) {
    return vsd_shortcut_result(opt);
  }
  const DepthImage de = render_model(renderer, mesh, T_est);
  const DepthImage dg = render_model(renderer, mesh, T_gt);
  return vsd_from_renders(de, dg, scene_depth, renderer.intrinsics(), diameter, opt);
}

BopPoseErrors bop_pose_errors(const Pose& T_est, const Pose& T_gt, const BopModel& model,
                              const Intrinsics& K, const BopErrorOptions& opt,
                              const DepthImage* scene_depth, DepthRenderer* renderer) {
  if (!model.mesh) throw std::invalid_argument("bop_pose_errors: the model has no mesh");
  BopPoseErrors e;
  const MssdResult ms = mssd(T_est, T_gt, model.mesh->vertices, model.symmetries);
  const MspdResult mp = mspd(T_est, T_gt, K, model.mesh->vertices, model.symmetries);
  e.mssd_mm = ms.error_mm;
  e.mssd_symmetry = ms.symmetry;
  e.mspd_px = mp.error_px;
  e.mspd_symmetry = mp.symmetry;
  if (opt.compute_vsd && scene_depth && renderer) {
    e.vsd = vsd(T_est, T_gt, *scene_depth, *model.mesh, model.diameter, *renderer, opt.vsd).errors;
  }
  return e;
}

BopImageErrors bop_image_errors(const BopImageInput& in, const std::map<int, BopModel>& models,
                                const BopErrorOptions& opt, DepthRenderer* renderer) {
  const size_t n_gt = in.gt_obj_ids.size();
  if (in.gt_poses.size() != n_gt || (!in.gt_valid.empty() && in.gt_valid.size() != n_gt)) {
    throw std::invalid_argument("bop_image_errors: gt_obj_ids, gt_poses and gt_valid differ in size");
  }
  BopImageErrors out;
  out.scene_id = in.scene_id;
  out.im_id = in.im_id;
  out.image_width = in.K.width;
  std::map<int, int> valid_count;
  for (size_t g = 0; g < n_gt; ++g) {
    BopTarget t;
    t.obj_id = in.gt_obj_ids[g];
    t.valid = in.gt_valid.empty() ? true : static_cast<bool>(in.gt_valid[g]);
    out.gts.push_back(t);
    if (t.valid) ++valid_count[t.obj_id];
  }
  const bool with_vsd = opt.compute_vsd && renderer && in.depth;
  std::map<int, DepthImage> gt_render;  // per GT index, rendered on demand

  std::vector<double> scores;
  std::vector<int> objs;
  for (const BopEstimate& e : in.estimates) {
    scores.push_back(e.score);
    objs.push_back(e.obj_id);
  }
  for (const auto& [obj_id, k] : valid_count) {
    auto mit = models.find(obj_id);
    if (mit == models.end() || !mit->second.mesh) {
      throw std::invalid_argument("bop_image_errors: no model for object " + std::to_string(obj_id));
    }
    const BopModel& model = mit->second;
    for (int ei : top_estimates(scores, objs, obj_id, k)) {
      const BopEstimate& est = in.estimates[ei];
      BopEstimateErrors ee;
      ee.obj_id = obj_id;
      ee.score = est.score;
      ee.diameter = model.diameter;
      ee.source = ei;
      DepthImage est_render;
      bool est_rendered = false;
      for (size_t g = 0; g < n_gt; ++g) {
        if (in.gt_obj_ids[g] != obj_id) continue;
        BopPairErrors p;
        p.gt = static_cast<int>(g);
        const Pose& T_gt = in.gt_poses[g];
        p.mssd_mm = mssd(est.T_cam_model, T_gt, model.mesh->vertices, model.symmetries).error_mm;
        p.mspd_px = mspd(est.T_cam_model, T_gt, in.K, model.mesh->vertices, model.symmetries).error_px;
        if (with_vsd) {
          if (opt.vsd.sphere_projection_shortcut &&
              !sphere_projections_overlap(0.5 * model.diameter, est.T_cam_model.t, T_gt.t)) {
            p.vsd.assign(opt.vsd.taus.size(), 1.0);
          } else {
            if (!est_rendered) {
              est_render = render_model(*renderer, *model.mesh, est.T_cam_model);
              est_rendered = true;
            }
            auto git = gt_render.find(static_cast<int>(g));
            if (git == gt_render.end()) {
              git = gt_render.emplace(static_cast<int>(g), render_model(*renderer, *model.mesh, T_gt)).first;
            }
            p.vsd = vsd_from_renders(est_render, git->second, *in.depth, renderer->intrinsics(),
                                     model.diameter, opt.vsd)
                        .errors;
          }
        }
        ee.pairs.push_back(std::move(p));
      }
      out.estimates.push_back(std::move(ee));
    }
  }
  return out;
}

}  // namespace pb
