// MSSD and MSPD on hand-made poses with known answers (and against a brute
// force of the toolkit's definition), and the BOP matching and recall on a
// hand-made list of errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/random.h"
#include "core/rotation.h"
#include "eval/bop_metrics.h"
#include "eval/symmetry.h"

using namespace pb;

namespace {

const double kDeg = M_PI / 180.0;

Pose some_gt() {
  Pose T;
  T.R = axis_angle(Vec3(0.3, -1.0, 0.4), 1.1);
  T.t = Vec3(-120, 45, 1350);
  return T;
}

// Points on the three axes at +-a, +-b, +-c.
std::vector<Vec3f> axis_points(float a, float b, float c) {
  return {{a, 0, 0}, {-a, 0, 0}, {0, b, 0}, {0, -b, 0}, {0, 0, c}, {0, 0, -c}};
}

std::vector<Vec3f> random_points(Rng& rng, int n, double extent) {
  std::vector<Vec3f> p;
  for (int i = 0; i < n; ++i) {
    p.push_back(Vec3(rng.uniform(-extent, extent), rng.uniform(-extent, extent),
                     rng.uniform(-0.5 * extent, 0.5 * extent))
                    .cast<float>());
  }
  return p;
}

// The toolkit's mssd / mspd, literally (no pruning, no reordering).
double brute_mssd(const Pose& e, const Pose& g, const std::vector<Vec3f>& pts, const std::vector<Pose>& syms) {
  double best = std::numeric_limits<double>::infinity();
  for (const Pose& S : syms) {
    const Pose gs = g * S;
    double m = 0;
    for (const Vec3f& p : pts) m = std::max(m, (e * p.cast<double>() - gs * p.cast<double>()).norm());
    best = std::min(best, m);
  }
  return best;
}

double brute_mspd(const Pose& e, const Pose& g, const Intrinsics& K, const std::vector<Vec3f>& pts,
                  const std::vector<Pose>& syms) {
  double best = std::numeric_limits<double>::infinity();
  for (const Pose& S : syms) {
    const Pose gs = g * S;
    double m = 0;
    for (const Vec3f& p : pts) {
      m = std::max(m, (K.project(e * p.cast<double>()) - K.project(gs * p.cast<double>())).norm());
    }
    best = std::min(best, m);
  }
  return best;
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

}  // namespace

TEST(EvalBopMetrics, Bop19Settings) {
  const std::vector<double> taus = bop19_vsd_taus();
  ASSERT_EQ(taus.size(), 10u);
  EXPECT_DOUBLE_EQ(taus.front(), 0.05);
  EXPECT_DOUBLE_EQ(taus.back(), 0.5);
  EXPECT_EQ(bop19_mssd_thresholds(), taus);
  EXPECT_EQ(bop19_vsd_thresholds(), taus);
  const std::vector<double> px = bop19_mspd_thresholds();
  ASSERT_EQ(px.size(), 10u);
  EXPECT_EQ(px.front(), 5.0);
  EXPECT_EQ(px.back(), 50.0);
}

TEST(EvalBopMetrics, MssdOfAPureTranslationIsItsLength) {
  Rng rng(3);
  const std::vector<Vec3f> pts = random_points(rng, 500, 80);
  const Pose gt = some_gt();
  for (double d : {0.5, 7.0, 42.0, 300.0}) {
    Pose est = gt;
    est.t += d * Vec3(1, -2, 2).normalized();
    EXPECT_NEAR(mssd(est, gt, pts, {}).error_mm, d, 1e-9);
  }
}

TEST(EvalBopMetrics, MssdOfARotationIsTheLargestDisplacement) {
  // Rotation by theta about the model's z: a point at distance r from the
  // axis moves 2 r sin(theta / 2); the furthest is a = 60 mm (b = 40 mm,
  // c = 100 mm lies on the axis and does not move).
  const std::vector<Vec3f> pts = axis_points(60, 40, 100);
  const Pose gt = some_gt();
  for (double deg : {1.0, 30.0, 90.0, 180.0}) {
    Pose S;
    S.R = axis_angle(Vec3::UnitZ(), deg * kDeg);
    const MssdResult r = mssd(gt * S, gt, pts, {});
    EXPECT_NEAR(r.error_mm, 2 * 60 * std::sin(deg * kDeg / 2), 1e-9) << deg;
  }
  // About x: the furthest point from the x axis is c = 100.
  Pose S;
  S.R = axis_angle(Vec3::UnitX(), 20 * kDeg);
  EXPECT_NEAR(mssd(gt * S, gt, pts, {}).error_mm, 2 * 100 * std::sin(10 * kDeg), 1e-9);
}

TEST(EvalBopMetrics, MssdWithSymmetriesIsNearZeroForASymmetricPose) {
  // A ring of points about z (a cylinder's rim) with a continuous symmetry.
  std::vector<Vec3f> ring;
  for (int i = 0; i < 72; ++i) {
    const double a = i * 5 * kDeg;
    ring.push_back(Vec3(50 * std::cos(a), 50 * std::sin(a), (i % 2) ? 30 : -30).cast<float>());
  }
  ContinuousSymmetry c;
  const std::vector<Pose> syms = symmetry_transformations({}, {c});
  const Pose gt = some_gt();
  // On the grid: exactly zero; off it, at most the half-step chord.
  Pose S;
  S.R = axis_angle(Vec3::UnitZ(), 100 * 2 * M_PI / 315);
  MssdResult r = mssd(gt * S, gt, ring, syms);
  EXPECT_LT(r.error_mm, 1e-9);
  EXPECT_EQ(r.symmetry, 100);
  S.R = axis_angle(Vec3::UnitZ(), 77.7 * kDeg);
  r = mssd(gt * S, gt, ring, syms);
  EXPECT_LE(r.error_mm, 2 * 50 * std::sin(0.5 * M_PI / 315) + 1e-9);
  // Without the symmetry it is the full chord.
  EXPECT_NEAR(mssd(gt * S, gt, ring, {}).error_mm, 2 * 50 * std::sin(77.7 * kDeg / 2), 1e-5);  // float points

  // A box with a 2-fold symmetry about z, turned half a turn: zero.
  Mat4 D = Mat4::Identity();
  D.block<3, 3>(0, 0) = axis_angle(Vec3::UnitZ(), M_PI);
  const std::vector<Pose> two = symmetry_transformations({D}, {});
  const std::vector<Vec3f> box = axis_points(60, 40, 100);
  S.R = axis_angle(Vec3::UnitZ(), M_PI);
  r = mssd(gt * S, gt, box, two);
  EXPECT_LT(r.error_mm, 1e-9);
  EXPECT_EQ(r.symmetry, 1);
  EXPECT_NEAR(mssd(gt * S, gt, box, {}).error_mm, 120.0, 1e-9);
}

TEST(EvalBopMetrics, MssdAndMspdEqualTheToolkitDefinitionOnRandomPoses) {
  Rng rng(11);
  const std::vector<Vec3f> pts = random_points(rng, 1000, 60);
  Mat4 D = Mat4::Identity();
  D.block<3, 3>(0, 0) = axis_angle(Vec3::UnitX(), M_PI);
  ContinuousSymmetry c;
  c.offset = Vec3(0, 2, 0);
  SymmetryOptions so;
  so.max_sym_disc_step = 0.05;  // 63 steps, 126 symmetries
  const std::vector<Pose> syms = symmetry_transformations({D}, {c}, so);
  const Intrinsics K = vga();
  for (int i = 0; i < 20; ++i) {
    Pose gt;
    gt.R = random_rotation(rng);
    gt.t = Vec3(rng.uniform(-200, 200), rng.uniform(-150, 150), rng.uniform(800, 2000));
    Pose est;
    est.R = axis_angle(Vec3(rng.normal(), rng.normal(), rng.normal()), rng.uniform(0, M_PI)) * gt.R;
    est.t = gt.t + Vec3(rng.normal(0, 30), rng.normal(0, 30), rng.normal(0, 30));
    EXPECT_NEAR(mssd(est, gt, pts, syms).error_mm, brute_mssd(est, gt, pts, syms), 1e-9);
    EXPECT_NEAR(mspd(est, gt, K, pts, syms).error_px, brute_mspd(est, gt, K, pts, syms), 1e-9);
  }
}

TEST(EvalBopMetrics, MspdOfAnImageShiftIsItsLength) {
  // A planar model facing the camera at depth Z: a translation parallel to
  // the image by d * Z / f mm shifts every projection by exactly d pixels.
  const Intrinsics K = vga();
  std::vector<Vec3f> planar;
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j) planar.push_back(Vec3f(10.f * i, 7.f * j, 0.f));
  Pose gt;
  gt.t = Vec3(30, -20, 1000);
  for (double d : {1.0, 5.0, 23.5}) {
    Pose est = gt;
    est.t += Vec3(3, 4, 0).normalized() * (d * 1000.0 / 570.0);
    EXPECT_NEAR(mspd(est, gt, K, planar, {}).error_px, d, 1e-9) << d;
  }
  // A 3D model: the nearest points move most, f * dx / z_min.
  const std::vector<Vec3f> pts = axis_points(50, 50, 100);  // z from 900 to 1100
  Pose est = gt;
  est.t.x() += 9.0;
  EXPECT_NEAR(mspd(est, gt, K, pts, {}).error_px, 570.0 * 9.0 / 900.0, 1e-9);
}

namespace {

BopPairErrors pair(int gt, double mssd_mm, double mspd_px, std::vector<double> vsd) {
  BopPairErrors p;
  p.gt = gt;
  p.mssd_mm = mssd_mm;
  p.mspd_px = mspd_px;
  p.vsd = std::move(vsd);
  return p;
}

BopEstimateErrors est(int obj, double score, std::vector<BopPairErrors> pairs) {
  BopEstimateErrors e;
  e.obj_id = obj;
  e.score = score;
  e.diameter = 100.0;
  e.pairs = std::move(pairs);
  return e;
}

// Image A: GTs 0, 1 of object 1, 2 of object 2, 3 of object 3 (not a
// target). Image B: one GT of object 1 and no estimate. Width 1280 (MSPD x 0.5).
std::vector<BopImageErrors> hand_errors() {
  BopImageErrors a;
  a.scene_id = 1;
  a.im_id = 0;
  a.image_width = 1280;
  a.gts = {{1, true}, {1, true}, {2, true}, {3, false}};
  const std::vector<double> far{1.0, 1.0};
  // Listed out of score order on purpose.
  a.estimates.push_back(est(1, 0.8, {pair(0, 14, 100, far), pair(1, 9, 100, far)}));        // eB
  a.estimates.push_back(est(1, 0.1, {pair(0, 1, 1, {0.0, 0.0}), pair(1, 1, 1, {0.0, 0.0})}));  // eC: 3rd of 2
  a.estimates.push_back(est(1, 0.9, {pair(0, 12, 100, {0.9, 0.9}), pair(1, 8, 100, {0.12, 0.02})}));  // eA
  a.estimates.push_back(est(2, 0.5, {pair(2, 31, 18, far)}));     // eD
  a.estimates.push_back(est(3, 1.0, {pair(3, 0, 0, {0.0, 0.0})}));  // eE: GT 3 is not a target
  BopImageErrors b;
  b.scene_id = 1;
  b.im_id = 1;
  b.gts = {{1, true}};
  return {a, b};
}

}  // namespace

TEST(EvalBopMetrics, RecallWithGreedyMatchingByScore) {
  const BopScores s = bop_scores(hand_errors());
  EXPECT_EQ(s.targets, 4);
  EXPECT_EQ(s.estimates, 3);  // eA, eB (top 2 of object 1), eD
  // MSSD (fractions of 100 mm): eA takes GT 1 (8 mm, its lowest) from 10 mm
  // on; eB then takes GT 0 (14 mm) from 15 mm; eD (31 mm) from 35 mm. eC
  // (1 mm) is not among the top 2 of object 1.
  const std::vector<double> mssd{0, 1, 2, 2, 2, 2, 3, 3, 3, 3};
  ASSERT_EQ(s.recall_mssd.size(), 10u);
  for (int i = 0; i < 10; ++i) EXPECT_DOUBLE_EQ(s.recall_mssd[i], mssd[i] / 4) << i;
  EXPECT_NEAR(s.ar_mssd, 21.0 / 40, 1e-15);
  // MSPD x 640 / 1280: only eD (18 px -> 9) from 10 px on; 100 -> 50 is not < 50.
  for (int i = 0; i < 10; ++i) EXPECT_DOUBLE_EQ(s.recall_mspd[i], i == 0 ? 0.0 : 0.25) << i;
  EXPECT_NEAR(s.ar_mspd, 9.0 / 40, 1e-15);
  // VSD, two taus: eA-GT 1 is 0.12 (matched from threshold 0.15) and 0.02
  // (from 0.05); nothing else under 0.5.
  ASSERT_EQ(s.recall_vsd.size(), 2u);
  for (int i = 0; i < 10; ++i) {
    EXPECT_DOUBLE_EQ(s.recall_vsd[0][i], i >= 2 ? 0.25 : 0.0) << i;
    EXPECT_DOUBLE_EQ(s.recall_vsd[1][i], 0.25) << i;
  }
  EXPECT_NEAR(s.ar_vsd, (8 + 10) / 20.0 * 0.25, 1e-15);
  EXPECT_NEAR(s.ar, (s.ar_vsd + s.ar_mssd + s.ar_mspd) / 3, 1e-15);
  EXPECT_NEAR(s.ar, (0.225 + 0.525 + 0.225) / 3, 1e-12);
}

TEST(EvalBopMetrics, HigherScoreChoosesFirst) {
  // Swap the scores of eA and eB: eB (now first) takes GT 1 (9 mm), eA then
  // takes GT 0 (12 mm) from 15 mm on.
  std::vector<BopImageErrors> im = hand_errors();
  im[0].estimates[0].score = 0.95;
  const BopScores s = bop_scores(im);
  EXPECT_DOUBLE_EQ(s.recall_mssd[1], 0.25);  // 10 mm: eB-GT1 only
  EXPECT_DOUBLE_EQ(s.recall_mssd[2], 0.5);   // 15 mm: and eA-GT0
  // Matching is per threshold: in VSD eB (1.0 to both) matches nothing, so
  // GT 1 stays free for eA (0.12 at tau 0) from threshold 0.15 on.
  for (int i = 0; i < 10; ++i) EXPECT_DOUBLE_EQ(s.recall_vsd[0][i], i >= 2 ? 0.25 : 0.0);
  // Greedy, not an optimal assignment: eB (first) has VSD 0.13 to GT 0 and
  // 0.08 to GT 1 at tau 0 and takes GT 1, its lowest; eA (0.12 to GT 1, 0.9
  // to GT 0) is left without a match, though eB-GT0 + eA-GT1 would make two.
  im[0].estimates[0].pairs[0].vsd = {0.13, 1.0};
  im[0].estimates[0].pairs[1].vsd = {0.08, 1.0};
  const BopScores s2 = bop_scores(im);
  for (int i = 0; i < 10; ++i) {
    EXPECT_DOUBLE_EQ(s2.recall_vsd[0][i], i >= 1 ? 0.25 : 0.0) << i;
    EXPECT_DOUBLE_EQ(s2.recall_vsd[1][i], 0.25) << i;  // tau 1: eA-GT1 (0.02)
  }
}

TEST(EvalBopMetrics, ScoresRejectBadPairs) {
  std::vector<BopImageErrors> im = hand_errors();
  im[0].estimates[0].pairs[0].gt = 7;
  EXPECT_THROW(bop_scores(im), std::invalid_argument);
  im = hand_errors();
  im[0].estimates[0].pairs[0].gt = 2;  // a GT of object 2
  EXPECT_THROW(bop_scores(im), std::invalid_argument);
  im = hand_errors();
  im[0].estimates[0].pairs[0].vsd = {1.0};
  EXPECT_THROW(bop_scores(im), std::invalid_argument);
}

TEST(EvalBopMetrics, NoTargetsGivesZeroRecall) {
  const BopScores s = bop_scores({});
  EXPECT_EQ(s.targets, 0);
  EXPECT_EQ(s.ar_mssd, 0.0);
  EXPECT_TRUE(std::isnan(s.ar_vsd));  // no VSD errors at all
  EXPECT_EQ(s.ar, 0.0);
}

TEST(EvalBopMetrics, ImageErrorsFromPoses) {
  // Two instances of a 2-fold symmetric object; three estimates: one exactly
  // on GT 1 turned by the symmetry, one 3 mm off GT 0, a low-score one.
  Mesh mesh;
  mesh.vertices = axis_points(60, 40, 100);
  mesh.faces = {{0, 2, 4}};
  Mat4 D = Mat4::Identity();
  D.block<3, 3>(0, 0) = axis_angle(Vec3::UnitZ(), M_PI);
  BopModel model;
  model.mesh = &mesh;
  model.symmetries = symmetry_transformations({D}, {});
  model.diameter = 200.0;

  BopImageInput in;
  in.K = vga();
  Pose g0 = some_gt(), g1 = some_gt();
  g1.t.x() += 300;
  in.gt_obj_ids = {5, 5};
  in.gt_poses = {g0, g1};
  Pose S;
  S.R = axis_angle(Vec3::UnitZ(), M_PI);
  Pose e1 = g0;
  e1.t += Vec3(0, 3, 0);
  in.estimates = {{5, 0.5, g1 * S}, {5, 0.7, e1}, {5, 0.1, g0}, {6, 1.0, g0}};
  const BopImageErrors im = bop_image_errors(in, {{5, model}}, BopErrorOptions{});
  ASSERT_EQ(im.estimates.size(), 2u);  // the top 2 of object 5; object 6 has no GT
  EXPECT_EQ(im.estimates[0].score, 0.7);
  ASSERT_EQ(im.estimates[0].pairs.size(), 2u);
  EXPECT_NEAR(im.estimates[0].pairs[0].mssd_mm, 3.0, 1e-9);
  EXPECT_NEAR(im.estimates[1].pairs[1].mssd_mm, 0.0, 1e-9);
  EXPECT_NEAR(im.estimates[1].pairs[1].mspd_px, 0.0, 1e-9);
  EXPECT_TRUE(im.estimates[0].pairs[0].vsd.empty());  // no renderer: no VSD
  const BopScores s = bop_scores({im});
  EXPECT_EQ(s.targets, 2);
  for (double r : s.recall_mssd) EXPECT_DOUBLE_EQ(r, 1.0);  // 3 mm < 0.05 * 200
  EXPECT_THROW(bop_image_errors(in, {}, BopErrorOptions{}), std::invalid_argument);
}
