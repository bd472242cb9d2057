// VSD: the formula on a hand-made strip of pixels, then with the OSMesa
// renderer: 0 for the ground-truth pose (also with an occluder and missing
// depth), 1 for a pose off the image, and a known answer for a depth shift.
#include <gtest/gtest.h>

#include <cmath>

#include "core/rotation.h"
#include "eval/bop_metrics.h"
#include "render/renderer.h"

using namespace pb;

namespace {

// An axis-aligned box centred at the origin with half extents (a, b, c).
Mesh box(float a, float b, float c) {
  Mesh m;
  for (int i = 0; i < 8; ++i) m.vertices.push_back({(i & 1) ? a : -a, (i & 2) ? b : -b, (i & 4) ? c : -c});
  const int q[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : q) {
    m.faces.push_back({f[0], f[1], f[2]});
    m.faces.push_back({f[0], f[2], f[3]});
  }
  return m;
}

Intrinsics vga() {
  Intrinsics K;
  K.width = 640;
  K.height = 480;
  K.fx = 570;
  K.fy = 570;
  K.cx = 319.5;
  K.cy = 239.5;
  return K;
}

DepthImage render(DepthRenderer& r, const std::vector<std::pair<const Mesh*, Pose>>& items) {
  std::vector<RenderItem> v;
  for (const auto& [m, T] : items) {
    RenderItem it;
    it.mesh = m;
    it.T_cam_model = T;
    v.push_back(it);
  }
  return r.render(v).depth;
}

// A wall at 1500 mm wherever nothing was rendered.
void add_wall(DepthImage& d) {
  for (float& z : d.z)
    if (z == 0.f) z = 1500.f;
}

long count_positive(const DepthImage& d) {
  long n = 0;
  for (float z : d.z) n += z > 0;
  return n;
}

}  // namespace

TEST(EvalVsd, FormulaOnAStripOfPixels) {
  // Five pixels, focal length so long that depth = distance exactly.
  Intrinsics K;
  K.width = 5;
  K.height = 1;
  K.fx = K.fy = 1e9;
  K.cx = 2;
  K.cy = 0;
  DepthImage gt(5, 1), est(5, 1), test(5, 1);
  // u0: GT only, visible.            u1: both, est 5 mm behind.
  // u2: both, est 50 mm behind the scene: visible because GT is (bop19).
  // u3: est only, 20 mm behind the scene: occluded.
  // u4: est only, no scene depth: visible (bop19).
  const float g[5] = {1000, 1000, 1000, 0, 0};
  const float e[5] = {0, 1005, 1050, 1020, 1100};
  const float t[5] = {1000, 1000, 1000, 1000, 0};
  for (int u = 0; u < 5; ++u) {
    gt.at(u, 0) = g[u];
    est.at(u, 0) = e[u];
    test.at(u, 0) = t[u];
  }
  VsdOptions opt;
  opt.taus = {0.01, 0.05, 0.1, 0.6};
  const VsdResult r = vsd_from_renders(est, gt, test, K, 100.0, opt);
  EXPECT_EQ(r.visible_gt_px, 3);
  EXPECT_EQ(r.visible_est_px, 3);
  EXPECT_EQ(r.intersection_px, 2);
  EXPECT_EQ(r.union_px, 4);
  // Distances / diameter on the intersection: 0.05 and 0.5; (cost + 2) / 4.
  ASSERT_EQ(r.errors.size(), 4u);
  EXPECT_DOUBLE_EQ(r.errors[0], 1.0);
  EXPECT_DOUBLE_EQ(r.errors[1], 1.0);  // 0.05 >= 0.05: the step cost counts it
  EXPECT_DOUBLE_EQ(r.errors[2], 0.75);
  EXPECT_DOUBLE_EQ(r.errors[3], 0.5);

  // Not normalized: taus in mm.
  opt.normalized_by_diameter = false;
  opt.taus = {10.0};
  EXPECT_DOUBLE_EQ(vsd_from_renders(est, gt, test, K, 100.0, opt).errors[0], 0.75);

  // Empty union: 1.
  const DepthImage empty(5, 1);
  EXPECT_DOUBLE_EQ(vsd_from_renders(empty, empty, test, K, 100.0, opt).errors[0], 1.0);
  // Sizes must match the intrinsics.
  EXPECT_THROW(vsd_from_renders(DepthImage(4, 1), gt, test, K, 100.0, opt), std::invalid_argument);
}

TEST(EvalVsd, ZeroForTheGroundTruthOneOffTheImage) {
  const Intrinsics K = vga();
  DepthRenderer r(K);
  const Mesh m = box(50, 40, 30);
  const double diameter = 2 * std::sqrt(50.0 * 50 + 40 * 40 + 30 * 30);
  Pose gt;
  gt.R = axis_angle(Vec3(1, 2, 0.5), 0.7);
  gt.t = Vec3(40, -30, 900);
  DepthImage scene = render(r, {{&m, gt}});
  ASSERT_GT(count_positive(scene), 2000);
  add_wall(scene);

  VsdResult v = vsd(gt, gt, scene, m, diameter, r);
  ASSERT_EQ(v.errors.size(), 10u);
  for (double e : v.errors) EXPECT_EQ(e, 0.0);
  EXPECT_GT(v.union_px, 2000);
  EXPECT_EQ(v.union_px, v.intersection_px);
  EXPECT_FALSE(v.shortcut);

  // Far to the side: outside the image.
  Pose off = gt;
  off.t = Vec3(5000, 0, 900);
  v = vsd(off, gt, scene, m, diameter, r);
  for (double e : v.errors) EXPECT_EQ(e, 1.0);
  EXPECT_TRUE(v.shortcut);
  VsdOptions no_shortcut;
  no_shortcut.sphere_projection_shortcut = false;
  v = vsd(off, gt, scene, m, diameter, r, no_shortcut);
  for (double e : v.errors) EXPECT_EQ(e, 1.0);
  EXPECT_FALSE(v.shortcut);
  EXPECT_EQ(v.visible_est_px, 0);
  EXPECT_EQ(v.intersection_px, 0);
  EXPECT_EQ(v.union_px, v.visible_gt_px);
  EXPECT_GT(v.union_px, 2000);

  // Behind the camera also renders nothing.
  off.t = Vec3(0, 0, -900);
  for (double e : vsd(off, gt, scene, m, diameter, r, no_shortcut).errors) EXPECT_EQ(e, 1.0);
}

TEST(EvalVsd, GroundTruthWithOccluderAndMissingDepthIsZero) {
  const Intrinsics K = vga();
  DepthRenderer r(K);
  const Mesh m = box(50, 40, 30);
  const Mesh occluder = box(30, 80, 5);
  const double diameter = 2 * std::sqrt(50.0 * 50 + 40 * 40 + 30 * 30);
  Pose gt;
  gt.R = axis_angle(Vec3(0.2, 1, 0), 0.5);
  gt.t = Vec3(0, 0, 900);
  Pose T_occ;
  T_occ.t = Vec3(-40, 0, 600);
  DepthImage scene = render(r, {{&m, gt}, {&occluder, T_occ}});
  add_wall(scene);
  // A hole in the measured depth over part of the object.
  for (int v = 230; v < 250; ++v)
    for (int u = 330; u < 360; ++u) scene.at(u, v) = 0.f;
  const VsdResult v = vsd(gt, gt, scene, m, diameter, r);
  for (double e : v.errors) EXPECT_EQ(e, 0.0);
  // The occluded part is not visible: fewer visible pixels than rendered.
  const long rendered = count_positive(render(r, {{&m, gt}}));
  EXPECT_LT(v.visible_gt_px, rendered - 500);
  EXPECT_GT(v.visible_gt_px, 500);
}

TEST(EvalVsd, DepthShiftOfAFrontoParallelFace) {
  // A box facing the camera on the optical axis shows only its front face
  // at 770 mm. The estimate 10 mm further: every shared pixel is off by
  // 10 mm * (distance / depth), 10.0 to 10.03 mm. Taus below that (0.05 x
  // 141 = 7.1 mm) count every pixel: error 1; above (0.1 x 141 = 14.1 mm)
  // only the rim the smaller silhouette leaves: (union - inter) / union,
  // about 1 - (770 / 780)^2 = 0.0255.
  const Intrinsics K = vga();
  DepthRenderer r(K);
  const Mesh m = box(50, 40, 30);
  const double diameter = 2 * std::sqrt(50.0 * 50 + 40 * 40 + 30 * 30);
  Pose gt;
  gt.t = Vec3(0, 0, 800);
  DepthImage scene = render(r, {{&m, gt}});
  add_wall(scene);
  Pose est = gt;
  est.t.z() += 10;
  const VsdResult v = vsd(est, gt, scene, m, diameter, r);
  EXPECT_EQ(v.visible_est_px, v.intersection_px);  // the farther silhouette is inside
  EXPECT_EQ(v.union_px, v.visible_gt_px);
  EXPECT_EQ(v.errors[0], 1.0);
  const double rim = static_cast<double>(v.union_px - v.intersection_px) / v.union_px;
  for (size_t k = 1; k < v.errors.size(); ++k) EXPECT_DOUBLE_EQ(v.errors[k], rim) << k;
  EXPECT_NEAR(rim, 1.0 - std::pow(770.0 / 780.0, 2), 0.01);
}

TEST(EvalVsd, ImageErrorsRenderEachGroundTruthOnce) {
  // bop_image_errors with a renderer: VSD per pair, equal to vsd() itself.
  const Intrinsics K = vga();
  DepthRenderer r(K);
  const Mesh m = box(50, 40, 30);
  BopModel model;
  model.mesh = &m;
  model.diameter = 2 * std::sqrt(50.0 * 50 + 40 * 40 + 30 * 30);
  Pose g0, g1;
  g0.t = Vec3(-150, 0, 900);
  g1.t = Vec3(150, 0, 900);
  g1.R = axis_angle(Vec3::UnitY(), 0.4);
  DepthImage scene = render(r, {{&m, g0}, {&m, g1}});
  add_wall(scene);
  Pose e0 = g0;
  e0.t.x() += 4;
  BopImageInput in;
  in.K = K;
  in.depth = &scene;
  in.gt_obj_ids = {1, 1};
  in.gt_poses = {g0, g1};
  in.estimates = {{1, 0.9, e0}, {1, 0.8, g1}};
  const BopImageErrors im = bop_image_errors(in, {{1, model}}, BopErrorOptions{}, &r);
  ASSERT_EQ(im.estimates.size(), 2u);
  const std::vector<double> direct = vsd(e0, g0, scene, m, model.diameter, r).errors;
  EXPECT_EQ(im.estimates[0].pairs[0].vsd, direct);
  for (double e : im.estimates[1].pairs[1].vsd) EXPECT_EQ(e, 0.0);
  const BopScores s = bop_scores({im});
  EXPECT_EQ(s.targets, 2);
  EXPECT_GT(s.ar_vsd, 0.5);
  EXPECT_DOUBLE_EQ(s.recall_mssd.back(), 1.0);
}
