// PPF (Drost et al. 2010) as a descriptor method (issue 3): on generated
// table scenes of an asymmetric object (1 mm noise), its best hypothesis and
// the whole pipeline (PPF + ICP point-to-plane + inlier verification) find
// the pose within the thesis's table thresholds (translation < 50 mm,
// 1 - |p.q| < 0.05) in at least the fraction measured, minus a margin. Also:
// trained state round trip, determinism, empty inputs, YAML parsing, and the
// voting's pieces against their definitions bit for bit (the pair feature
// against PCL's, the alpha bins against the formula).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "core/cpu.h"
#include "core/error.h"
#include "core/rotation.h"
#include "core/yaml.h"
#include "recognition/kdtree.h"
#include "recognition/method.h"
#include "recognition/pipeline.h"
#include "recognition/ppf/internal.h"
#include "recognition_train_util.h"
#include "test_recognition_refine_scenes.h"

namespace pb {
namespace {

constexpr int kScenes = 10;
constexpr uint64_t kSeed = 20100613;

bool correct(const Pose& est, const Pose& gt) {
  const double dq = std::abs(to_quaternion(est.R).dot(to_quaternion(gt.R)));
  return (est.t - gt.t).norm() < 50.0 && 1.0 - dq < 0.05;
}

// The model's 12 training views as the pipeline prepares them (rendered,
// preprocessed at the default voxel), for the method-level tests.
std::vector<ViewData> training_views(const Mesh& object) {
  std::vector<ViewData> views;
  const auto dirs = refine_test::training_directions();
  for (size_t k = 0; k < dirs.size(); ++k) {
    const auto tv = refine_test::training_view(object, dirs[k], derive_seed(kSeed, {k}));
    views.push_back(ViewData{tv.cloud_cam, tv.T_cam_model});
  }
  return views;
}

class PpfScenes : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!cases_.empty()) return;
    object_ = refine_test::asymmetric_object();
    refine_test::CaseOptions o;
    o.with_model_view = false;
    for (int i = 0; i < kScenes; ++i) cases_.push_back(refine_test::make_case(object_, i, kSeed, o));
    views_ = training_views(object_);
    method_ = make_ppf_method(settings_.ppf);
    method_->train(views_, settings_.seed);
  }
  static Mesh object_;
  static std::vector<refine_test::Case> cases_;
  static std::vector<ViewData> views_;
  static std::unique_ptr<Method> method_;
  static RecognitionSettings settings_;
};
Mesh PpfScenes::object_;
std::vector<refine_test::Case> PpfScenes::cases_;
std::vector<ViewData> PpfScenes::views_;
std::unique_ptr<Method> PpfScenes::method_;
RecognitionSettings PpfScenes::settings_ = [] {
  RecognitionSettings s;
  s.descriptor = "ppf";
  s.refinement = "icp_plane";
  return s;
}();

TEST_F(PpfScenes, BestHypothesisFindsThePose) {
  int best_ok = 0, any_ok = 0;
  for (size_t i = 0; i < cases_.size(); ++i) {
    const auto& c = cases_[i];
    StageTimes t;
    const auto hyps = method_->hypothesize(c.scene, views_, derive_seed(kSeed, {i}), t);
    ASSERT_FALSE(hyps.empty()) << "scene " << i;
    EXPECT_LE(hyps.size(), static_cast<size_t>(settings_.ppf.max_hypotheses));
    bool any = false;
    for (const auto& h : hyps) {
      any = any || correct(h.T_cam_model, c.gt);
      EXPECT_GE(h.view, 0);
      EXPECT_LT(h.view, static_cast<int>(views_.size()));
    }
    for (size_t k = 1; k < hyps.size(); ++k) EXPECT_GE(hyps[k - 1].score, hyps[k].score);
    const bool best = correct(hyps.front().T_cam_model, c.gt);
    best_ok += best;
    any_ok += any;
    std::printf("  scene %zu: %zu scene points, %zu hypotheses, best: votes %.0f, t %.1f mm, R %.1f deg %s%s\n", i,
                c.scene.size(), hyps.size(), hyps.front().score,
                refine_test::translation_error(hyps.front().T_cam_model, c.gt),
                refine_test::rotation_error_deg(hyps.front().T_cam_model, c.gt), best ? "ok" : "wrong",
                any ? "" : " (none correct)");
  }
  std::printf("PPF best hypothesis correct in %d of %d scenes, some hypothesis in %d\n", best_ok, kScenes, any_ok);
  EXPECT_GE(best_ok, 7);
  EXPECT_GE(any_ok, 8);
}

TEST_F(PpfScenes, PipelineWithPpfFindsThePose) {
  const auto model = test::train(object_, settings_, TrainOptions{}, nullptr, "asymmetric");
  int ok = 0;
  for (size_t i = 0; i < cases_.size(); ++i) {
    const auto& c = cases_[i];
    const RecognitionResult r = recognize(c.depth, c.K, *model, settings_);
    const bool good = r.status == "ok" && correct(r.T_cam_model, c.gt);
    ok += good;
    std::printf("  scene %zu: %s, inliers %d, t %.1f mm, R %.2f deg, %.2f s\n", i, r.status.c_str(), r.inliers,
                refine_test::translation_error(r.T_cam_model, c.gt),
                refine_test::rotation_error_deg(r.T_cam_model, c.gt), r.times.total());
  }
  std::printf("PPF + icp_plane pipeline correct in %d of %d scenes\n", ok, kScenes);
  EXPECT_GE(ok, 8);
}

TEST_F(PpfScenes, TrainedStateRoundTripsAndMatchingIsDeterministic) {
  BinaryWriter ss;
  method_->save(ss);
  auto loaded = make_ppf_method(settings_.ppf);
  BinaryReader in(ss.buffer(), "test");
  loaded->load(in);
  EXPECT_TRUE(in.at_end());
  const auto& c = cases_[0];
  StageTimes t;
  const auto a = method_->hypothesize(c.scene, views_, 5, t);
  const auto b = loaded->hypothesize(c.scene, views_, 5, t);
  const auto again = method_->hypothesize(c.scene, views_, 5, t);
  ASSERT_FALSE(a.empty());
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), again.size());
  for (size_t k = 0; k < a.size(); ++k) {
    for (const auto* o : {&b[k], &again[k]}) {
      EXPECT_EQ(std::memcmp(a[k].T_cam_model.R.data(), o->T_cam_model.R.data(), sizeof(double) * 9), 0);
      EXPECT_EQ(std::memcmp(a[k].T_cam_model.t.data(), o->T_cam_model.t.data(), sizeof(double) * 3), 0);
      EXPECT_EQ(a[k].score, o->score);
      EXPECT_EQ(a[k].view, o->view);
    }
  }
  // A corrupt state is an error, not a crash.
  const std::string bad = ss.buffer().substr(0, 40), junk = "not a ppf state at all";
  BinaryReader bad_in(bad, "test"), junk_in(junk, "test");
  EXPECT_THROW(make_ppf_method(settings_.ppf)->load(bad_in), std::runtime_error);
  EXPECT_THROW(make_ppf_method(settings_.ppf)->load(junk_in), std::runtime_error);
}

TEST_F(PpfScenes, EmptyInputsGiveNoHypothesis) {
  StageTimes t;
  PointSet empty;
  EXPECT_TRUE(method_->hypothesize(empty, views_, 1, t).empty());
  PointSet no_normals = cases_[0].scene;
  no_normals.normals.clear();
  EXPECT_TRUE(method_->hypothesize(no_normals, views_, 1, t).empty());
  auto untrained = make_ppf_method(settings_.ppf);
  untrained->train({}, settings_.seed);
  EXPECT_TRUE(untrained->hypothesize(cases_[0].scene, views_, 1, t).empty());
  BinaryWriter ss;
  untrained->save(ss);
  auto loaded = make_ppf_method(settings_.ppf);
  BinaryReader in(ss.buffer(), "test");
  loaded->load(in);
  EXPECT_TRUE(loaded->hypothesize(cases_[0].scene, views_, 1, t).empty());
}

// Our pair feature against pcl::computePairFeatures, bit for bit (the
// scene's keys must be the model table's, which PCL computes): random
// pairs, pairs whose two cosines tie or nearly tie (PCL's acos comparison
// decides them), cosines rounded above 1, signed zeros, coincident points,
// normals along the line, NaN.
TEST(PpfPairFeature, EqualsPclBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> pos(-150.f, 150.f), unit(-1.f, 1.f);
  auto normal = [&] {
    Vec3f n(unit(rng), unit(rng), unit(rng));
    return n.norm() > 1e-3f ? Vec3f(n.normalized()) : Vec3f(0, 0, 1);
  };
  auto nudge = [](Vec3f v, int ulps) {
    for (int k = 0; k < ulps; ++k) v.x() = std::nextafter(v.x(), 2.f);
    return v;
  };
  size_t checked = 0, ties = 0, mismatched = 0;
  auto check = [&](const Vec3f& p1, const Vec3f& n1, const Vec3f& p2, const Vec3f& n2) {
    float a[4], b[4];
    const bool ra = ppf::pair_feature(p1, n1, p2, n2, a), rb = ppf::pcl_pair_feature(p1, n1, p2, n2, b);
    ++checked;
    if (ra != rb || std::memcmp(a, b, sizeof a) != 0) {
      if (++mismatched <= 5)
        ADD_FAILURE() << "p1 " << p1.transpose() << " n1 " << n1.transpose() << " p2 " << p2.transpose() << " n2 "
                      << n2.transpose() << ": ours " << ra << " " << a[0] << " " << a[1] << " " << a[2] << " "
                      << a[3] << ", PCL " << rb << " " << b[0] << " " << b[1] << " " << b[2] << " " << b[3];
    }
  };
  for (int i = 0; i < 400000; ++i) {
    const Vec3f p1(pos(rng), pos(rng), pos(rng)), p2(pos(rng), pos(rng), pos(rng));
    const Vec3f n1 = normal();
    check(p1, n1, p2, normal());
    // n2 mirrored across the plane normal to the line: |cos| ties up to
    // rounding; then nudged by a few ulps either way.
    const Vec3f d = (p2 - p1).normalized();
    const Vec3f m = n1 - 2 * n1.dot(d) * d;
    for (int u = 0; u < 4; ++u) {
      check(p1, n1, p2, nudge(m, u));
      check(p1, nudge(n1, u), p2, m);
      ties += 2;
    }
    check(p1, n1, p2, -m);
    ties += 1;
  }
  // Axis-aligned cases: exact zeros, signed zeros, cosines of exactly 1.
  const float vals[] = {0.f, -0.f, 1.f, -1.f, 10.f};
  const Vec3f axes[] = {Vec3f(1, 0, 0), Vec3f(0, 1, 0), Vec3f(0, 0, 1), Vec3f(-1, 0, 0), Vec3f(0, -0.f, -1),
                        Vec3f(-0.f, -0.f, 1)};
  for (float x : vals)
    for (float y : vals)
      for (float z : vals)
        for (const Vec3f& n1 : axes)
          for (const Vec3f& n2 : axes) check(Vec3f(0, 0, 0), n1, Vec3f(x, y, z), n2);
  // Cosines rounded above 1: a normal of norm slightly above 1 along the line.
  for (int i = 0; i < 20000; ++i) {
    const Vec3f p1(pos(rng), pos(rng), pos(rng)), p2(pos(rng), pos(rng), pos(rng));
    const Vec3f d = (p2 - p1).normalized();
    check(p1, nudge(d, 1 + i % 3), p2, normal());
    check(p1, normal(), p2, nudge(-d, 1 + i % 3));
  }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  check(Vec3f(0, 0, 0), Vec3f(0, 0, 1), Vec3f(1, 2, 3), Vec3f(nan, 0, 0));
  check(Vec3f(0, 0, 0), Vec3f(nan, nan, nan), Vec3f(1, 2, 3), Vec3f(0, 0, 1));
  check(Vec3f(1, 2, 3), Vec3f(0, 0, 1), Vec3f(1, 2, 3), Vec3f(0, 1, 0));
  EXPECT_EQ(mismatched, 0u) << "of " << checked << " pairs (" << ties << " near ties)";
}

// The alpha bin from each bin's first float equals PCL's formula: every
// float within 2000 ulps of each bin edge, and a million random ones, for
// the default 12 degrees and two steps that do not divide 360.
TEST(PpfAlphaBins, EqualTheFormula) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> any(-3.3f, 3.3f);
  for (const double deg : {12.0, 7.0, 25.3}) {
    const float step = static_cast<float>(deg * M_PI / 180.0);
    const int n = std::max(1, static_cast<int>(std::floor(2 * M_PI / step)));
    const ppf::AlphaBins bins(step, n);
    size_t wrong = 0, checked = 0;
    auto check = [&](float a) {
      ++checked;
      if (bins(a) != bins.exact(a) && ++wrong <= 3) ADD_FAILURE() << deg << " deg, alpha " << a;
    };
    for (int k = 0; k <= n; ++k) {
      float a = static_cast<float>(k * static_cast<double>(step) - M_PI);
      for (int u = 0; u < 2000; ++u) a = std::nextafter(a, -4.f);
      for (int u = 0; u < 4000; ++u, a = std::nextafter(a, 4.f)) check(a);
    }
    for (int i = 0; i < 1000000; ++i) check(any(rng));
    for (float a : {-0.f, 0.f, -3.2f, 3.2f, static_cast<float>(M_PI), -static_cast<float>(M_PI)}) check(a);
    EXPECT_EQ(wrong, 0u) << deg << " deg, of " << checked;
  }
}

// Voting's cells eight at a time (AVX2, the bin from its formula in double)
// equal the one-at-a-time path (AlphaBins): around every bin edge and the
// wrap at +-pi, with alpha_s at random, and at random, for the default 12
// degrees and two steps that do not divide 360; lengths that are not a
// multiple of eight take the one-at-a-time tail.
TEST(PpfVoteCells, EightAtATimeEqualOneAtATime) {
  if (!pb::cpu_has_avx2()) GTEST_SKIP() << "this CPU has no AVX2: voting takes the one-at-a-time path only";
  std::mt19937 rng(12);
  const float pi = static_cast<float>(M_PI);
  std::uniform_real_distribution<float> any(-pi, pi);
  for (const double deg : {12.0, 7.0, 25.3}) {
    const float step = static_cast<float>(deg * M_PI / 180.0);
    const int n_alpha = std::max(1, static_cast<int>(std::floor(2 * M_PI / step)));
    const ppf::VoteCells cells(step, n_alpha);
    std::vector<float> alpha_m;
    std::vector<uint32_t> ref;
    size_t wrong = 0, checked = 0;
    auto check = [&](float alpha_s) {
      ref.resize(alpha_m.size());
      for (size_t k = 0; k < ref.size(); ++k) ref[k] = static_cast<uint32_t>(rng() % 1000);
      std::vector<uint32_t> got(alpha_m.size()), want(alpha_m.size());
      cells(ref.data(), alpha_m.data(), alpha_m.size(), alpha_s, got.data());
      cells.plain(ref.data(), alpha_m.data(), alpha_m.size(), alpha_s, want.data());
      for (size_t k = 0; k < got.size(); ++k, ++checked)
        if (got[k] != want[k] && ++wrong <= 3)
          ADD_FAILURE() << deg << " deg, alpha_m " << alpha_m[k] << ", alpha_s " << alpha_s;
      alpha_m.clear();
    };
    for (int t = 0; t < 40; ++t) {
      const float alpha_s = t == 0 ? pi : t == 1 ? -pi : any(rng);
      // alpha_m near alpha_s + each bin edge, the edges one turn away, and +-pi.
      for (int k = -n_alpha - 1; k <= 2 * n_alpha + 1; ++k) {
        const double edge = k * static_cast<double>(step) - M_PI;
        for (const double target : {alpha_s + edge, alpha_s + edge - 2 * M_PI, static_cast<double>(pi),
                                    -static_cast<double>(pi), alpha_s + M_PI, alpha_s - M_PI}) {
          if (target < -pi || target > pi) continue;
          float a = static_cast<float>(target);
          for (int u = 0; u < 20; ++u) a = std::nextafter(a, -4.f);
          for (int u = 0; u < 43; ++u, a = std::nextafter(a, 4.f))
            if (a >= -pi && a <= pi) alpha_m.push_back(a);
        }
      }
      check(alpha_s);
    }
    for (int t = 0; t < 1000; ++t) {
      alpha_m.resize(1000 + t % 8);
      for (float& a : alpha_m) a = any(rng);
      check(any(rng));
    }
    EXPECT_EQ(wrong, 0u) << deg << " deg, of " << checked;
    EXPECT_GT(checked, 1000000u);
  }
}

// PPF's f1 bin (ppf::atan2_bin, core/atan2_bin.h with feature_bin) equals
// the bin of atan2f's angle on random directions at every scale and on
// special values, for the default 12 degrees and a step that does not divide
// 360; the directions at bin edges are tested with the same bins in
// test_core_atan2_bin.cpp.
TEST(PpfAtan2Bin, EqualsTheBinOfAtan2f) {
  Rng rng(13);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  const float special[] = {0.f, -0.f, 1.f, -1.f, 1e-30f, -1e-45f, 3e38f, inf, -inf, nan};
  for (const double deg : {12.0, 7.0}) {
    const float step = static_cast<float>(deg * M_PI / 180.0);
    size_t wrong = 0, checked = 0;
    auto check = [&](float y, float x) {
      ++checked;
      if (ppf::atan2_bin(y, x, step) != ppf::feature_bin(std::atan2(y, x), step) && ++wrong <= 3)
        ADD_FAILURE() << deg << " deg, y " << y << " x " << x;
    };
    for (int i = 0; i < 500000; ++i) {
      const float scale = std::ldexp(1.f, rng.uniform_int(-40, 40));
      check(static_cast<float>(rng.uniform(-1, 1)) * scale, static_cast<float>(rng.uniform(-1, 1)) * scale);
    }
    for (float y : special)
      for (float x : special) check(y, x);
    EXPECT_EQ(wrong, 0u) << deg << " deg, of " << checked;
  }
}

// pcl_alpha's sign test without sinf equals sinf's: every float within 5000
// ulps of +-3.14159274 (the float nearest pi, beyond it) and of +-1e-20,
// tiny and subnormal angles, random ones, against z of both signs from
// subnormal to large, and zeros, NaN, angles beyond the float pi.
TEST(PpfSinSign, EqualsSinfTimesZ) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> angle(-3.2f, 3.2f);
  const float zs[] = {1.f, -1.f, 1e-20f, -1e-20f, 9.99e-21f, 1e-30f, -1e-38f, 1e-45f, -1e-45f, 0.f, -0.f, 123.f,
                      -3e38f, std::numeric_limits<float>::quiet_NaN()};
  size_t wrong = 0, checked = 0;
  auto check = [&](float a) {
    for (float z : zs) {
      ++checked;
      if (ppf::sin_times_negative(a, z) != (std::sin(a) * z < 0.0f) && ++wrong <= 3)
        ADD_FAILURE() << "a " << a << " z " << z;
    }
  };
  const float pi = static_cast<float>(M_PI);
  for (const float centre : {pi, -pi, 1e-20f, -1e-20f}) {
    float a = centre;
    for (int u = 0; u < 5000; ++u) a = std::nextafter(a, -4.f);
    for (int u = 0; u < 10000; ++u, a = std::nextafter(a, 4.f)) check(a);
  }
  for (int e = -149; e < 2; ++e) {
    check(std::ldexp(1.f, e));
    check(-std::ldexp(1.f, e));
  }
  for (int i = 0; i < 300000; ++i) check(angle(rng));
  for (const float a : {0.f, -0.f, 3.3f, -3.3f, std::numeric_limits<float>::infinity(),
                        std::numeric_limits<float>::quiet_NaN()})
    check(a);
  EXPECT_EQ(wrong, 0u) << "of " << checked;
}

// ppf::vote, written plainly from its definition: every other scene point
// within the model's diameter paired with the reference (in the kd-tree's
// order, as vote takes them: with vote_once the first pair of a (key,
// alpha_s bin) votes, so the order counts), the pair's key looked up in the sorted table,
// each (key, alpha_s bin) voting once per reference point (a std::set), an
// accumulator per reference point, its best cell the most votes, the lowest
// cell among equals. With a partner cloud pc: the partners are its points
// (none skipped), the references still every scene point.
std::vector<ppf::PoseVote> plain_vote(const ppf::Model& m, const PointSet& scene, const PointSet* pc = nullptr) {
  const int n_alpha = std::max(1, static_cast<int>(std::floor(2 * M_PI / m.angle_step)));
  const ppf::AlphaBins bins(m.angle_step, n_alpha);
  const PointSet& second = pc ? *pc : scene;
  const KdTree3 tree(second.points);
  std::vector<ppf::PoseVote> out;
  std::vector<int> partners;
  for (size_t r = 0; r < scene.size(); ++r) {
    const Vec3f sr = scene.points[r], nr = scene.normals[r];
    const Eigen::Affine3f T_sg = ppf::to_reference_frame(sr, nr);
    std::map<uint32_t, uint32_t> acc;
    std::set<std::pair<uint64_t, int>> voted;
    tree.radius_unsorted(sr, m.diameter, partners);
    for (const int pi : partners) {
      const size_t i = static_cast<size_t>(pi);
      float f[4];
      if ((!pc && i == r) || !ppf::pair_feature(sr, nr, second.points[i], second.normals[i], f)) continue;
      if (!std::isfinite(f[0]) || !std::isfinite(f[1]) || !std::isfinite(f[2]) || !std::isfinite(f[3])) continue;
      const uint64_t key = ppf::feature_key(f[0], f[1], f[2], f[3], m.angle_step, m.distance_step);
      const auto range = std::equal_range(m.table.begin(), m.table.end(), key, [](const auto& a, const auto& b) {
        if constexpr (std::is_same_v<std::decay_t<decltype(a)>, uint64_t>) return a < b.key;
        else return a.key < b;
      });
      if (range.first == range.second) continue;
      const float alpha_s = ppf::pcl_alpha(T_sg, second.points[i]);
      if (!std::isfinite(alpha_s)) continue;
      const int alpha_s_bin = static_cast<int>(std::floor((alpha_s + M_PI) / m.angle_step));
      if (!voted.insert({key, alpha_s_bin}).second) continue;
      for (auto e = range.first; e != range.second; ++e)
        ++acc[e->ref * static_cast<uint32_t>(n_alpha) + static_cast<uint32_t>(bins.exact(ppf::wrapped_alpha(e->alpha_m, alpha_s)))];
    }
    if (acc.empty()) continue;
    auto best = acc.begin();
    for (auto it = acc.begin(); it != acc.end(); ++it)
      if (it->second > best->second) best = it;
    const size_t mr = best->first / static_cast<uint32_t>(n_alpha);
    const float alpha = static_cast<float>((best->first % static_cast<uint32_t>(n_alpha) + 0.5) * m.angle_step - M_PI);
    const Eigen::Affine3f T = T_sg.inverse() * Eigen::AngleAxisf(alpha, Vec3f::UnitX()) *
                              ppf::to_reference_frame(m.points[mr], m.normals[mr]);
    ppf::PoseVote pv;
    pv.pose.R = T.linear().cast<double>();
    pv.pose.t = T.translation().cast<double>();
    pv.votes = best->second;
    out.push_back(pv);
  }
  return out;
}

// A model of 120 points (in a 100 mm cube, random normals; or on a plane,
// its normal +z) with every pair's feature, its table at `deg` degrees and a
// distance step of a quarter of the diameter.
ppf::Model vote_test_model(bool plane, double deg) {
  Rng rng(21);
  ppf::Model m;
  for (int k = 0; k < 120; ++k) {
    const float z = plane ? 0.f : static_cast<float>(rng.uniform(-50, 50));
    m.points.emplace_back(static_cast<float>(rng.uniform(-50, 50)), static_cast<float>(rng.uniform(-50, 50)), z);
    m.normals.push_back(plane ? Vec3f::UnitZ()
                              : Vec3f(static_cast<float>(rng.normal()), static_cast<float>(rng.normal()),
                                      static_cast<float>(rng.normal()))
                                    .normalized());
  }
  const size_t n = m.points.size();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      float f[4];
      const float nan = std::numeric_limits<float>::quiet_NaN();
      ppf::PairFeature pf{nan, nan, nan, nan, nan};
      if (i != j && ppf::pair_feature(m.points[i], m.normals[i], m.points[j], m.normals[j], f))
        pf = {f[0], f[1], f[2], f[3], ppf::pcl_alpha(ppf::to_reference_frame(m.points[i], m.normals[i]), m.points[j])};
      m.features.push_back(pf);
    }
  m.angle_step = static_cast<float>(deg * M_PI / 180.0);
  m.distance_step = 0.25f * 142.f;
  ppf::build_table(m);
  return m;
}

// The most votes a reference point of `scene` can cast with every other
// point: the sum of its pairs' table ranges (voting counts in 16 bits up to
// 65535 of them).
size_t most_votes_of_a_reference(const ppf::Model& m, const PointSet& scene) {
  size_t most = 0;
  for (size_t r = 0; r < scene.size(); ++r) {
    size_t sum = 0;
    for (size_t i = 0; i < scene.size(); ++i) {
      float f[4];
      if (i == r || !ppf::pair_feature(scene.points[r], scene.normals[r], scene.points[i], scene.normals[i], f))
        continue;
      const uint64_t key = ppf::feature_key(f[0], f[1], f[2], f[3], m.angle_step, m.distance_step);
      sum += static_cast<size_t>(
          std::count_if(m.table.begin(), m.table.end(), [key](const auto& e) { return e.key == key; }));
    }
    most = std::max(most, sum);
  }
  return most;
}

// ppf::vote with vote_once equals plain_vote on two models. One whose pairs
// share few keys: points on a plane, so every pair has the same angles and
// the distance bin alone tells keys apart, and a reference point meets one
// key with alpha_s in every bin; its references cast more votes than 16 bits
// count. And random points, whose references cast few, so both of voting's
// accumulators are compared. At 12 degrees (30 alpha bins) and at 4 degrees
// (90 bins, more than the 64 flags of one word: bins 64 apart must not share
// a flag).
TEST(PpfVote, VoteOnceEqualsAPlainReference) {
  for (const auto& [plane, deg] : {std::pair{true, 12.0}, {true, 4.0}, {false, 12.0}, {false, 4.0}}) {
    ppf::Model m = vote_test_model(plane, deg);
    const size_t n = m.points.size();
    ASSERT_FALSE(m.table.empty());
    m.diameter = 1000;  // every scene point a partner: no radius boundary to agree on
    // The scene: the model moved.
    const Eigen::Matrix3f R = Eigen::AngleAxisf(0.7f, Vec3f(1, 2, 3).normalized()).toRotationMatrix();
    const Vec3f t(30, -20, 600);
    PointSet scene;
    for (size_t i = 0; i < n; ++i) {
      scene.points.push_back(R * m.points[i] + t);
      scene.normals.push_back(R * m.normals[i]);
    }
    std::vector<int> refs(n);
    for (size_t i = 0; i < n; ++i) refs[i] = static_cast<int>(i);
    if (deg == 12.0) {
      const size_t most = most_votes_of_a_reference(m, scene);
      if (plane) EXPECT_GT(most, 65535u) << "the plane's references need 32-bit counts";
      else EXPECT_LE(most, 65535u) << "the random points' references fit 16-bit counts";
    }
    ppf::VoteOptions opt;
    opt.vote_once = true;
    // Partners of their own (scene_partner_steps): every third scene point,
    // in reverse, and the scene itself passed as partners, which pairs a
    // reference with its own point too: that pair has no feature, so the
    // votes are those of the scene alone.
    PointSet third;
    for (size_t i = n; i-- > 0;)
      if (i % 3 == 0) {
        third.points.push_back(scene.points[i]);
        third.normals.push_back(scene.normals[i]);
      }
    const std::vector<ppf::PoseVote> alone = plain_vote(m, scene);
    const struct {
      const char* what;
      std::vector<ppf::PoseVote> got, want;
    } cases[] = {{"scene", ppf::vote(m, scene, refs, opt), alone},
                 {"every third point", ppf::vote(m, scene, refs, opt, &third), plain_vote(m, scene, &third)},
                 {"the scene as partners", ppf::vote(m, scene, refs, opt, &scene), alone}};
    for (const auto& c : cases) {
      ASSERT_EQ(c.got.size(), c.want.size()) << (plane ? "plane, " : "random, ") << deg << " deg, " << c.what;
      size_t differ = 0;
      for (size_t k = 0; k < c.got.size(); ++k) {
        const bool same = c.got[k].votes == c.want[k].votes && (c.got[k].pose.R - c.want[k].pose.R).norm() < 1e-9 &&
                          (c.got[k].pose.t - c.want[k].pose.t).norm() < 1e-9;
        if (!same && ++differ <= 3)
          ADD_FAILURE() << (plane ? "plane, " : "random, ") << deg << " deg, " << c.what << ", reference " << k
                        << ": " << c.got[k].votes
                        << " votes, want " << c.want[k].votes;
      }
      EXPECT_EQ(differ, 0u) << (plane ? "plane, " : "random, ") << deg << " deg, " << c.what << ", of "
                            << c.got.size();
    }
    // Fewer partners, fewer votes: the partner cloud is used.
    EXPECT_LT(cases[1].got[0].votes, cases[0].got[0].votes) << deg << " deg";
  }
}

// Pose clustering with its grid of cluster leads equals the plain greedy
// scan (each pose, most votes first, joins the first cluster in creation
// order whose lead is within both thresholds): random poses around a few
// centres at spreads near the thresholds, translations exactly a threshold
// apart, equal votes, and non-finite translations (never rejected by the
// distance test), every hypothesis the same bits.
TEST(PpfClusterPoses, GridEqualsThePlainScan) {
  const auto plain = [](std::vector<ppf::PoseVote> poses, const PpfSettings& s) {
    std::stable_sort(poses.begin(), poses.end(),
                     [](const ppf::PoseVote& a, const ppf::PoseVote& b) { return a.votes > b.votes; });
    struct C {
      Pose lead;
      Eigen::Quaterniond q;
      Vec3 t = Vec3::Zero();
      Eigen::Vector4d qs = Eigen::Vector4d::Zero();
      double votes = 0;
      int n = 0;
    };
    std::vector<C> cs;
    for (const auto& pv : poses) {
      const Eigen::Quaterniond q(pv.pose.R);
      C* home = nullptr;
      for (auto& c : cs) {
        if ((pv.pose.t - c.lead.t).norm() >= s.position_cluster_mm) continue;
        if (std::abs(Eigen::AngleAxisd(c.lead.R.transpose() * pv.pose.R).angle()) >=
            s.rotation_cluster_deg * M_PI / 180.0)
          continue;
        home = &c;
        break;
      }
      if (!home) {
        cs.push_back({pv.pose, q});
        home = &cs.back();
      }
      home->t += pv.pose.t;
      Eigen::Vector4d qc = q.coeffs();
      if (qc.dot(home->q.coeffs()) < 0) qc = -qc;
      home->qs += qc;
      home->votes += pv.votes;
      ++home->n;
    }
    std::stable_sort(cs.begin(), cs.end(), [](const C& a, const C& b) { return a.votes > b.votes; });
    if (cs.size() > static_cast<size_t>(s.max_hypotheses)) cs.resize(static_cast<size_t>(s.max_hypotheses));
    std::vector<Hypothesis> out;
    for (const auto& c : cs) {
      Hypothesis h;
      h.T_cam_model.t = c.t / c.n;
      Eigen::Quaterniond q;
      q.coeffs() = c.qs.normalized();
      h.T_cam_model.R = q.toRotationMatrix();
      h.score = c.votes;
      out.push_back(h);
    }
    return out;
  };
  std::mt19937_64 rng(5);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uni(0, 1);
  int compared = 0;
  for (int trial = 0; trial < 60; ++trial) {
    PpfSettings s;
    s.position_cluster_mm = trial % 3 == 0 ? 30 : 5 + 50 * uni(rng);
    s.rotation_cluster_deg = 10 + 40 * uni(rng);
    s.max_hypotheses = trial % 2 ? 5 : 1000;
    std::vector<ppf::PoseVote> poses;
    const int centres = 1 + trial % 6;
    for (int i = 0; i < 400; ++i) {
      ppf::PoseVote pv;
      const int c = i % centres;
      const double spread = s.position_cluster_mm * (0.2 + 2 * uni(rng));
      pv.pose.t = Vec3(100.0 * c, 50.0 * c, 800) + spread * Vec3(normal(rng), normal(rng), normal(rng));
      pv.pose.R = Eigen::AngleAxisd(0.5 * c + 0.6 * normal(rng) * uni(rng),
                                    Vec3(normal(rng), normal(rng), normal(rng)).normalized())
                      .toRotationMatrix();
      pv.votes = std::floor(20 * uni(rng));  // many equal counts: the stable order matters
      poses.push_back(pv);
      if (i % 50 == 7) {  // a twin exactly one threshold away along x
        pv.pose.t.x() += s.position_cluster_mm;
        poses.push_back(pv);
      }
    }
    if (trial % 5 == 4) poses[static_cast<size_t>(trial % 17)].pose.t.y() = std::numeric_limits<double>::quiet_NaN();
    if (trial % 7 == 6) poses[3].pose.t.z() = 1e12;  // beyond the grid: scanned
    const auto want = plain(poses, s);
    const auto got = ppf::cluster_poses(poses, s);
    ASSERT_EQ(got.size(), want.size()) << "trial " << trial;
    for (size_t k = 0; k < got.size(); ++k) {
      EXPECT_EQ(got[k].score, want[k].score) << "trial " << trial << " hypothesis " << k;
      for (int j = 0; j < 3; ++j) {
        const double a = got[k].T_cam_model.t[j], b = want[k].T_cam_model.t[j];
        EXPECT_TRUE(a == b || (std::isnan(a) && std::isnan(b))) << "trial " << trial << " hypothesis " << k;
      }
      EXPECT_TRUE(got[k].T_cam_model.R == want[k].T_cam_model.R) << "trial " << trial << " hypothesis " << k;
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000);
}

TEST(Ppf, ParseReadsEveryFieldAndRejectsBadOnes) {
  const YamlNode n = YamlNode::load_string(
      "ppf:\n  model_points: 200\n  angle_step_deg: 10\n  distance_step_fraction: 0.04\n"
      "  scene_reference_fraction: 0.5\n  position_cluster_mm: 20\n  rotation_cluster_deg: 15\n"
      "  max_hypotheses: 3\n",
      "cfg.yaml");
  PpfSettings s;
  parse_section(n["ppf"], s);
  EXPECT_EQ(s.model_points, 200);
  EXPECT_EQ(s.angle_step_deg, 10);
  EXPECT_EQ(s.distance_step_fraction, 0.04);
  EXPECT_EQ(s.scene_reference_fraction, 0.5);
  EXPECT_EQ(s.position_cluster_mm, 20);
  EXPECT_EQ(s.rotation_cluster_deg, 15);
  EXPECT_EQ(s.max_hypotheses, 3);
  auto fails = [](const std::string& text, const std::string& field) {
    PpfSettings t;
    try {
      parse_section(YamlNode::load_string(text, "bad.yaml")["ppf"], t);
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), "bad.yaml");
      EXPECT_EQ(e.field(), field) << e.what();
      return;
    }
    ADD_FAILURE() << "no error for " << text;
  };
  fails("ppf:\n  model_pointz: 3\n", "ppf.model_pointz");
  fails("ppf:\n  model_points: 5\n", "ppf.model_points");
  fails("ppf:\n  model_points: 100000\n", "ppf.model_points");
  fails("ppf:\n  scene_reference_fraction: 1.5\n", "ppf.scene_reference_fraction");
  fails("ppf:\n  angle_step_deg: 0\n", "ppf.angle_step_deg");
  fails("ppf:\n  max_hypotheses: 0\n", "ppf.max_hypotheses");
}

}  // namespace
}  // namespace pb
