// Every descriptor (fpfh shot cvfh esf cesf ourcvfh ppf), each with ICP
// refinement, through train_model / recognize on one small fixed set of
// generated, UNOCCLUDED table scenes of an asymmetric object (the Stanford
// bunny, 150 mm, read from ../shared/models) with the synthetic sensor's 1 mm
// Gaussian depth noise and 2-4 distractors (issue 3, "Must show"): the
// fraction of images whose chosen pose is correct by the thesis's table
// thresholds (translation < 50 mm and 1 - |p.q| < 0.05) must stay at or
// above the measured fraction minus a margin. The bunny has no symmetry (the
// test checks its registry entry declares none), so these plain errors are
// exactly eval/errors.h's thesis_errors (which a test_recognition_* test
// cannot link: it links pb_recognition and its dependencies only).
// Each model is trained once and reused across the images.
//
// ESF: the thesis found 0% and blamed its 12 training views. The second test
// runs ESF trained with 12, 40 and 80 views on the same images and checks
// what was measured (see kEsfMinCorrect): more views help, but ESF is not at
// 0% on this object even with 12.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/rotation.h"
#include "core/yaml.h"
#include "models/registry.h"
#include "recognition/pipeline.h"
#include "recognition/registry.h"
#include "recognition_train_util.h"
#include "scenes/generator.h"
#include "scenes/scene_config.h"

namespace pb {
namespace {

constexpr char kScenes[] = R"(
scenario: table
seed: 33
images: 8
sensor: synthetic                        # 512 x 512, 30 x 30 deg
noise: {model: gaussian, sigma_mm: 1.0}
target: bunny
target_upright_probability: 0.5
min_target_visib: 0.9                    # unoccluded: (almost) all of the bunny's silhouette visible
distractors: {pool: [milk_carton, boletus, box_small, cylinder], count: [2, 4]}
occlusion: none
camera: {distance_mm: [600, 1000], elevation_deg: [30, 70]}
)";

// Minimum correct images of the 8, per descriptor (default settings: 12
// training views; ICP refinement). Measured on this set (the same with 1 and
// 2 OpenMP threads): fpfh 8, shot 8, cvfh 7, esf 5, cesf 1, ourcvfh 4, ppf 8.
// On 30 images of another seed (34) the same settings gave fpfh 30, shot 28,
// cvfh 28, esf 21, cesf 4, ourcvfh 25, ppf 28 of 30. Margin: 2 images.
//
// CESF (1 of 8; 4 of 30) is asserted at its measured value, without a margin,
// so that it cannot silently fall to 0%. It fails at matching, not at
// verification: in the wrong images none of its 15 refined hypotheses is
// correct (the test prints this). CESF describes each stable (smooth) region
// by an ESF of that region alone; the bunny's curved surface breaks into
// many small regions whose ESFs (shape distributions normalized to the
// region's size) look alike, and like the smooth faces of the distractors,
// so the top 5 matches over all scene regions rarely pair the right regions:
// of the 7 wrong poses chosen here, 4 lie on the cylinder, 1 on the milk
// carton and 2 on the bunny with a wrong rotation (measured once). The
// thesis saw the same with its Statue of Liberty (CVFH and CESF 0%: "divided
// the point clouds into many small clusters that were less descriptive").
// CVFH keeps working here because its histogram also describes the whole
// cluster (the VFH part), not only the region.
// These fractions are at the stage headers' mm values and the thesis's
// inlier ranking. At the default profile (lengths relative to the bunny's
// 191 mm diameter, verify.score visibility) the same 8 images gave (measured
// once): cesf 0, cvfh 6, esf 6, fpfh 8, ourcvfh 5, ppf 8, shot 8. CESF's 0:
// only one image of 8 had a correct hypothesis among its 15, ranked 3rd; the
// hypotheses, not the verification, are what CESF lacks here (see above).
const std::map<std::string, int> kMinCorrect = {
    {"fpfh", 6}, {"shot", 6}, {"cvfh", 5}, {"esf", 3}, {"cesf", 1}, {"ourcvfh", 2}, {"ppf", 6},
};

// ESF trained with N views (12: the thesis's ring of 8 plus 4 from below;
// 40 and 80: evenly spread over the sphere; 80 as ESF's authors used).
// Measured on this set: 12 views 5, 40 views 7, 80 views 7 of 8 correct (on
// the 30 images of seed 34: 21, 24, 27 of 30). So ESF is not at the thesis's
// 0% even with 12 views on this object, and more views do help: with 80
// views it must do strictly better than with 12. Margin: 2 images.
// These counts are at the stage headers' mm values (voxel 10 mm, ...). At
// the relative default profile (the bunny's diameter is 191 mm: voxel 9.6
// mm, inlier threshold 9.6 mm, cluster tolerance 19 mm, ...) the same set
// gave 7, 8, 7 of 8 (measured once): 12 views already find 7, so on these
// 8 images the comparison would say nothing.
const std::map<int, int> kEsfMinCorrect = {{12, 3}, {40, 5}, {80, 5}};

struct SceneSet {
  std::unique_ptr<SceneGenerator> gen;
  std::vector<GeneratedImage> images;
  Mesh mesh;
};

// The thesis's table thresholds (the introduction of its chapter 4).
constexpr double kMaxTranslationMm = 50.0;
constexpr double kMaxRotation = 0.05;  // 1 - |p.q|, about 36.4 deg

double rotation_error(const Mat3& a, const Mat3& b) {
  return 1.0 - std::abs(to_quaternion(a).dot(to_quaternion(b)));
}

struct Outcome {
  int correct = 0;
  int images = 0;
};

class AllDescriptors : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string why;
    if (!ModelRegistry::load_default().available("bunny", &why)) {
      skip_reason_ = new std::string(why);
      return;
    }
    set_ = new SceneSet;
    const SceneSettings ss =
        parse_scene_settings(YamlNode::load_string(kScenes, "all_descriptors_test_scenes.yaml"));
    set_->gen = std::make_unique<SceneGenerator>(ss);
    const SceneModel& bunny = set_->gen->model("bunny");
    set_->mesh = bunny.mesh;
    if (!bunny.info.symmetries_discrete.empty() || !bunny.info.symmetries_continuous.empty())
      symmetric_ = true;  // the plain errors below would be wrong: fail in SetUp
    for (int i = 0; i < ss.images; ++i) {
      set_->images.push_back(set_->gen->generate(i));
      const GeneratedImage& im = set_->images.back();
      std::printf("image %d: camera %.0f mm, elevation %.0f deg, target visible %.2f, %zu objects\n", i,
                  im.camera_distance_mm, im.camera_elevation_deg, im.info.gt_info.at(0).visib_fract,
                  im.info.gt.size());
    }
  }
  static void TearDownTestSuite() {
    delete set_;
    set_ = nullptr;
    delete skip_reason_;
    skip_reason_ = nullptr;
  }
  void SetUp() override {
    if (skip_reason_)
      GTEST_SKIP() << "the asymmetric target (shared model bunny, ../shared/models/bunny.obj) is unavailable: "
                   << *skip_reason_;
    ASSERT_FALSE(symmetric_) << "models.yaml declares a symmetry for the bunny; this test's errors assume none";
  }

  // Trains once with `s`, recognizes every image, prints one line per image.
  static Outcome run(const RecognitionSettings& s, const std::string& label) {
    const auto model = test::train(set_->mesh, s);
    const TrainedModelInfo info = trained_model_info(*model);
    EXPECT_FALSE(info.empty) << label << ": " << info.empty_reason;
    Outcome o;
    for (size_t i = 0; i < set_->images.size(); ++i) {
      const GeneratedImage& im = set_->images[i];
      const Pose& gt = im.info.gt.at(0).T_cam_model;
      const RecognitionResult r = recognize(im.depth, im.info.K, *model, s);
      bool ok = false;
      if (r.status == "ok") {
        const double te = (r.T_cam_model.t - gt.t).norm(), re = rotation_error(r.T_cam_model.R, gt.R);
        ok = te < kMaxTranslationMm && re < kMaxRotation;
        // Diagnostics: how many refined hypotheses were correct, and the rank
        // (by inliers) of the first one; "-" = none (a matching failure
        // rather than a verification one).
        int n_correct = 0, first = -1;
        for (size_t h = 0; h < r.hypotheses.size(); ++h) {
          const Pose& p = r.hypotheses[h].T_cam_model;
          if ((p.t - gt.t).norm() < kMaxTranslationMm && rotation_error(p.R, gt.R) < kMaxRotation) {
            if (first < 0) first = static_cast<int>(h);
            ++n_correct;
          }
        }
        char rank[16] = "-";
        if (first >= 0) std::snprintf(rank, sizeof rank, "%d", first);
        std::printf("  %-16s image %zu: %-7s translation %7.1f mm, 1-|p.q| %.4f, %4d inliers; %2d of %2zu "
                    "hypotheses correct, first at rank %s; %.2f s\n",
                    label.c_str(), i, ok ? "correct" : "wrong", te, re, r.inliers, n_correct, r.hypotheses.size(),
                    rank, r.times.total());
      } else {
        std::printf("  %-16s image %zu: %s (%s)\n", label.c_str(), i, r.status.c_str(), r.message.c_str());
      }
      o.correct += ok;
      ++o.images;
    }
    std::printf("%-16s %d / %d correct (%.0f%%), %d training views\n", label.c_str(), o.correct, o.images,
                100.0 * o.correct / o.images, info.views);
    std::fflush(stdout);
    return o;
  }

  static SceneSet* set_;
  static std::string* skip_reason_;
  static bool symmetric_;
};
SceneSet* AllDescriptors::set_ = nullptr;
std::string* AllDescriptors::skip_reason_ = nullptr;
bool AllDescriptors::symmetric_ = false;

TEST_F(AllDescriptors, EveryDescriptorFindsThePoseInTheMeasuredFraction) {
  std::map<std::string, Outcome> outcomes;
  for (const std::string& name : descriptor_names()) {
    ASSERT_TRUE(kMinCorrect.count(name)) << "no measured fraction for descriptor '" << name << "'";
    RecognitionSettings s;
    s.relative.clear();          // the mm values and the ranking these fractions were measured with
    s.verify.score = "inliers";  // (see kMinCorrect)
    s.descriptor = name;
    s.refinement = "icp";
    outcomes[name] = run(s, name + "+icp");
  }
  std::printf("summary (correct of %zu unoccluded bunny images):", set_->images.size());
  for (const auto& [name, o] : outcomes) std::printf(" %s %d", name.c_str(), o.correct);
  std::printf("\n");
  for (const auto& [name, o] : outcomes)
    EXPECT_GE(o.correct, kMinCorrect.at(name)) << name << "+icp: " << o.correct << " / " << o.images << " correct";
}

TEST_F(AllDescriptors, EsfWithMoreTrainingViews) {
  std::map<int, Outcome> outcomes;
  for (const auto& [views, min_correct] : kEsfMinCorrect) {
    RecognitionSettings s;
    s.relative.clear();  // the thesis's mm values and ranking these counts were measured with (see
    s.verify.score = "inliers";  // kEsfMinCorrect)
    s.descriptor = "esf";
    s.refinement = "icp";
    s.views.views = views;
    outcomes[views] = run(s, "esf+icp " + std::to_string(views) + "v");
  }
  for (const auto& [views, o] : outcomes)
    EXPECT_GE(o.correct, kEsfMinCorrect.at(views)) << "esf with " << views << " views: " << o.correct << " / "
                                                   << o.images << " correct";
  EXPECT_GT(outcomes.at(80).correct, outcomes.at(12).correct)
        << "ESF with 80 training views no longer beats ESF with 12 on this set";
}

}  // namespace
}  // namespace pb
