// PPF (Drost et al. 2010) as a descriptor method (issue 3): on generated
// table scenes of an asymmetric object (1 mm noise), its best hypothesis and
// the whole pipeline (PPF + ICP point-to-plane + inlier verification) find
// the pose within the thesis's table thresholds (translation < 50 mm,
// 1 - |p.q| < 0.05) in at least the fraction measured, minus a margin. Also:
// trained state round trip, determinism, empty inputs, YAML parsing.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <sstream>

#include "core/error.h"
#include "core/rotation.h"
#include "core/yaml.h"
#include "recognition/method.h"
#include "recognition/pipeline.h"
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
