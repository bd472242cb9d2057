// The local pipeline (FPFH, SHOT) end to end through train_model / recognize
// on a small fixed set of generated, unoccluded table scenes of an
// asymmetric object (the Stanford bunny, 150 mm) with 1 mm Gaussian depth
// noise and 2-4 distractors: the fraction of images whose chosen pose is
// correct by the thesis's table thresholds (translation < 50 mm and
// 1 - |p.q| < 0.05) must stay at or above the measured fraction minus a
// margin. Also: the same pose bit for bit with 1 and 2 threads.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <map>
#include <memory>

#include "core/rotation.h"
#include "core/yaml.h"
#include "models/registry.h"
#include "recognition/pipeline.h"
#include "recognition_train_util.h"
#include "scenes/generator.h"
#include "scenes/scene_config.h"

namespace pb {
namespace {

constexpr char kScenes[] = R"(
scenario: table
seed: 21
images: 10
sensor: synthetic        # 512 x 512, 30 deg, gaussian noise 1 mm
target: bunny
target_upright_probability: 0.5
min_target_visib: 0.9    # unoccluded
distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [2, 4]}
occlusion: none
camera: {distance_mm: [600, 1000], elevation_deg: [30, 70]}
)";

// Measured on this set with the default settings (12 views, ICP refinement):
// FPFH 10/10, SHOT 10/10. On 30 images of another seed the same settings gave
// FPFH 30/30 and SHOT 27/30, so the margin is 2 images.
const std::map<std::string, int> kMinCorrect = {{"fpfh", 8}, {"shot", 8}};

double rotation_error(const Mat3& a, const Mat3& b) {
  return 1.0 - std::abs(to_quaternion(a).dot(to_quaternion(b)));
}

struct SceneSet {
  std::unique_ptr<SceneGenerator> gen;
  std::vector<GeneratedImage> images;
  Mesh mesh;
};

class LocalScenes : public ::testing::TestWithParam<std::string> {
 protected:
  static void SetUpTestSuite() {
    std::string why;
    if (!ModelRegistry::load_default().available("bunny", &why)) {
      skip_reason_ = new std::string(why);
      return;
    }
    set_ = new SceneSet;
    const SceneSettings ss = parse_scene_settings(YamlNode::load_string(kScenes, "local_test_scenes.yaml"));
    set_->gen = std::make_unique<SceneGenerator>(ss);
    set_->mesh = set_->gen->model("bunny").mesh;
    for (int i = 0; i < ss.images; ++i) set_->images.push_back(set_->gen->generate(i));
  }
  static void TearDownTestSuite() {
    delete set_;
    set_ = nullptr;
    delete skip_reason_;
    skip_reason_ = nullptr;
  }
  void SetUp() override {
    if (skip_reason_) GTEST_SKIP() << "shared model bunny unavailable: " << *skip_reason_;
  }
  static SceneSet* set_;
  static std::string* skip_reason_;
};
SceneSet* LocalScenes::set_ = nullptr;
std::string* LocalScenes::skip_reason_ = nullptr;

TEST_P(LocalScenes, FindsThePoseInMostImages) {
  RecognitionSettings s;
  s.descriptor = GetParam();
  const auto model = test::train(set_->mesh, s);
  int correct = 0;
  for (size_t i = 0; i < set_->images.size(); ++i) {
    const GeneratedImage& im = set_->images[i];
    const Pose& gt = im.info.gt.at(0).T_cam_model;
    const RecognitionResult r = recognize(im.depth, im.info.K, *model, s);
    const double te = (r.T_cam_model.t - gt.t).norm(), re = rotation_error(r.T_cam_model.R, gt.R);
    const bool ok = r.status == "ok" && te < 50.0 && re < 0.05;
    correct += ok;
    std::printf("  %s image %zu: %s, %zu hypotheses, translation error %.1f mm, 1-|p.q| %.4f, %d inliers\n",
                s.descriptor.c_str(), i, ok ? "correct" : "wrong", r.hypotheses.size(), te, re, r.inliers);
  }
  std::printf("%s: %d / %zu correct\n", s.descriptor.c_str(), correct, set_->images.size());
  EXPECT_GE(correct, kMinCorrect.at(GetParam()));
}

TEST_P(LocalScenes, SamePoseWithOneAndTwoThreads) {
  RecognitionSettings s;
  s.descriptor = GetParam();
  s.views.views = 8;
  const auto model = test::train(set_->mesh, s);
  const GeneratedImage& im = set_->images.at(0);
  s.local.threads = 1;
  const RecognitionResult a = recognize(im.depth, im.info.K, *model, s);
  s.local.threads = 2;
  const RecognitionResult b = recognize(im.depth, im.info.K, *model, s);
  ASSERT_EQ(a.hypotheses.size(), b.hypotheses.size());
  ASSERT_FALSE(a.hypotheses.empty());
  for (size_t i = 0; i < a.hypotheses.size(); ++i) {
    EXPECT_EQ(0, std::memcmp(a.hypotheses[i].T_cam_model.R.data(), b.hypotheses[i].T_cam_model.R.data(),
                             9 * sizeof(double)));
    EXPECT_EQ(0, std::memcmp(a.hypotheses[i].T_cam_model.t.data(), b.hypotheses[i].T_cam_model.t.data(),
                             3 * sizeof(double)));
  }
  EXPECT_EQ(0, std::memcmp(a.T_cam_model.t.data(), b.T_cam_model.t.data(), 3 * sizeof(double)));
}

INSTANTIATE_TEST_SUITE_P(Descriptors, LocalScenes, ::testing::Values("fpfh", "shot"));

}  // namespace
}  // namespace pb
