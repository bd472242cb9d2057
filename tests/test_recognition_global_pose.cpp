// Each global descriptor (cvfh, esf, cesf, ourcvfh) finds the pose of an
// asymmetric object on rendered, unoccluded views (1 mm Gaussian noise, no
// table), within the thesis's table thresholds (50 mm, 1 - |p.q| < 0.05).
// The clouds are preprocessed as the pipeline does (plane removal off: there
// is no table); hypotheses are refined (ICP point-to-point, the thesis's
// table choice) and the one with the most inliers is taken, as recognize()
// does.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>

#include "core/timer.h"
#include "recognition/refine/refine.h"
#include "recognition/verify/verify.h"
#include "recognition/registry.h"
#include "test_recognition_global_util.h"

namespace pb {
namespace {

using namespace testing_global;

struct Outcome {
  int images = 0;
  int with_hypothesis = 0;
  int initial_any = 0;   // some initial hypothesis (top K, before refinement) is correct
  int refined_any = 0;   // some refined hypothesis is correct
  int chosen = 0;        // the hypothesis with most inliers after refinement is correct
  double seconds = 0;    // hypothesize, per image
  double fraction(int n) const { return images ? static_cast<double>(n) / images : 0.0; }
};

// Scene poses: the object upright (as on a table) seen from azimuths spread
// around it (never a training azimuth), elevations 20-40 degrees, the camera
// rolled by up to 10 degrees, at 600-800 mm.
std::vector<Pose> scene_poses(int n) {
  std::vector<Pose> poses;
  for (int i = 0; i < n; ++i) {
    const double az = 17.0 + 360.0 * i / n;
    const double el = 20.0 + 10.0 * (i % 3);
    const double roll = (i % 2 ? -1.0 : 1.0) * 5.0 * (i % 3);
    poses.push_back(camera_pose(az, el, roll, 600 + 100 * (i % 3)));
  }
  return poses;
}

// Any orientation (uniformly random rotations, seeded), 700 mm ahead with up
// to 60 mm sideways: viewpoints far from the training views too.
std::vector<Pose> random_poses(int n) {
  std::vector<Pose> poses;
  Rng rng(2016);
  for (int i = 0; i < n; ++i) {
    Pose T;
    T.R = random_rotation(rng);
    T.t = Vec3(rng.uniform(-60, 60), rng.uniform(-60, 60), 700);
    poses.push_back(T);
  }
  return poses;
}

Outcome evaluate(const std::string& descriptor, const Mesh& mesh, RecognitionSettings s,
                 const std::vector<Pose>& poses) {
  s.descriptor = descriptor;
  const std::vector<ViewData> views = training_views(mesh, s);
  std::unique_ptr<Method> method = make_method(s);
  method->train(views, s.seed);
  // The model clouds of the views (model frame), the refinement's sources.
  std::vector<PointSet> model_clouds;
  for (const auto& v : views) {
    PointSet m = v.cloud;
    const Pose T = v.T_cam_model.inverse();
    for (auto& p : m.points) p = (T * p.cast<double>()).cast<float>();
    for (auto& n : m.normals) n = (T.R * n.cast<double>()).cast<float>();
    model_clouds.push_back(std::move(m));
  }
  PreprocessSettings pre = s.preprocess;
  pre.remove_plane = false;  // no table in these images
  const Intrinsics K = synthetic_camera();
  Outcome o;
  for (size_t i = 0; i < poses.size(); ++i) {
    const Pose& gt = poses[i];
    const PointSet scene = preprocess_scene(render_cloud(mesh, gt, K, 1.0, 100 + i), pre, 200 + i);
    ++o.images;
    StageTimes times;
    Timer timer;
    const auto hyps = method->hypothesize(scene, views, derive_seed(s.seed, {i}), times);
    o.seconds += timer.seconds();
    if (hyps.empty()) continue;
    ++o.with_hypothesis;
    bool init_ok = false, ref_ok = false;
    int best_inliers = -1;
    Pose best;
    const PointIndex index(scene.points);
    for (size_t h = 0; h < hyps.size(); ++h) {
      init_ok = init_ok || correct(hyps[h].T_cam_model, gt);
      const RefineResult r = refine_pose(s.refinement, model_clouds[hyps[h].view], scene, hyps[h].T_cam_model,
                                         s.refine, derive_seed(s.seed, {i, h}));
      ref_ok = ref_ok || correct(r.T_cam_model, gt);
      const int inl = count_inliers(model_clouds[hyps[h].view].points, r.T_cam_model, index,
                                    s.verify.inlier_threshold_mm);
      if (inl > best_inliers) best_inliers = inl, best = r.T_cam_model;
    }
    if (std::getenv("PB_TEST_VERBOSE")) {
      std::printf("  image %zu: %zu hypotheses, chosen %s (t %.1f mm, r %.3f)\n", i, hyps.size(),
                  correct(best, gt) ? "ok" : "WRONG", translation_error(best, gt), rotation_error(best, gt));
      for (size_t h = 0; h < hyps.size(); ++h)
        std::printf("    view %2d score %.4f  initial t %7.1f mm r %.3f\n", hyps[h].view, hyps[h].score,
                    translation_error(hyps[h].T_cam_model, gt), rotation_error(hyps[h].T_cam_model, gt));
    }
    o.initial_any += init_ok;
    o.refined_any += ref_ok;
    o.chosen += correct(best, gt);
  }
  o.seconds /= std::max(o.images, 1);
  return o;
}

void report(const char* label, const Outcome& o) {
  std::printf("%-28s images %2d  with hypotheses %2d  initial(any of top K) %5.1f%%  refined(any) %5.1f%%  chosen %5.1f%%  (%.3f s/image)\n",
              label, o.images, o.with_hypothesis, 100 * o.fraction(o.initial_any), 100 * o.fraction(o.refined_any),
              100 * o.fraction(o.chosen), o.seconds);
}

class GlobalPose : public ::testing::Test {
 public:
  static void SetUpTestSuite() { mesh_ = new Mesh(asymmetric_object()); }
  static void TearDownTestSuite() {
    delete mesh_;
    mesh_ = nullptr;
  }
  static const Mesh& mesh() { return *mesh_; }
  static RecognitionSettings settings() {
    RecognitionSettings s;
    s.refinement = "icp";
    s.views.views = 12;
    return s;
  }
  static Mesh* mesh_;
};
Mesh* GlobalPose::mesh_ = nullptr;

constexpr int kImages = 12;

// The fractions measured on these images (chosen pose correct), minus a
// margin of two images, are asserted.
struct Pair {
  Outcome upright, any;
};
Pair check(const std::string& descriptor, int views, double min_upright, double min_any) {
  RecognitionSettings s = GlobalPose::settings();
  s.views.views = views;
  const std::string label = descriptor + ", " + std::to_string(views) + " views";
  Pair p;
  p.upright = evaluate(descriptor, GlobalPose::mesh(), s, scene_poses(kImages));
  report((label + ", upright").c_str(), p.upright);
  p.any = evaluate(descriptor, GlobalPose::mesh(), s, random_poses(kImages));
  report((label + ", any rotation").c_str(), p.any);
  EXPECT_EQ(p.upright.with_hypothesis, p.upright.images);
  EXPECT_EQ(p.any.with_hypothesis, p.any.images);
  EXPECT_GE(p.upright.fraction(p.upright.chosen), min_upright) << label;
  EXPECT_GE(p.any.fraction(p.any.chosen), min_any) << label;
  return p;
}

// Measured (12 + 12 images): upright 100%, any rotation 83%.
TEST_F(GlobalPose, Cvfh) { check("cvfh", 12, 0.83, 0.66); }
// Measured: upright 58%, any rotation 67% (the ESFs of flat regions look
// alike: many near-equal matches).
TEST_F(GlobalPose, Cesf) { check("cesf", 12, 0.41, 0.5); }
// "Skip CRH" (Table 4.4): the object upright, the roll taken from the view
// (the scene cameras are rolled by up to 10 degrees). Measured: cvfh 100%,
// cesf 67% (every image has a correct hypothesis among the top K; the
// flipped ones sometimes win on inliers).
TEST_F(GlobalPose, SkipCrhUpright) {
  for (const std::string d : {"cvfh", "cesf"}) {
    RecognitionSettings s = GlobalPose::settings();
    s.global.skip_crh = true;
    const Outcome o = evaluate(d, GlobalPose::mesh(), s, scene_poses(kImages));
    report((d + ", 12 views, skip CRH").c_str(), o);
    EXPECT_GE(o.fraction(o.chosen), d == "cvfh" ? 0.83 : 0.5) << d;
    EXPECT_GE(o.fraction(o.initial_any), 0.83) << d;
  }
}

// Measured: upright 100%, any rotation 83%.
TEST_F(GlobalPose, OurCvfh) { check("ourcvfh", 12, 0.83, 0.66); }
// Measured: upright 100%, any rotation 92% after ICP (initial poses: 33%
// correct among the top K for any rotation).
TEST_F(GlobalPose, Esf) { check("esf", 12, 0.83, 0.75); }
// More views: the initial poses of ESF for any rotation improve (measured
// 33% with 12 views, 83% with 40 and 80); after ICP all are good
// (measured 92%, 83%, 75%).
TEST_F(GlobalPose, EsfMoreViews) {
  RecognitionSettings s = GlobalPose::settings();
  const Outcome few = evaluate("esf", GlobalPose::mesh(), s, random_poses(kImages));
  const Pair p40 = check("esf", 40, 0.83, 0.66);
  const Pair p80 = check("esf", 80, 0.83, 0.58);
  EXPECT_GE(p40.any.fraction(p40.any.initial_any), few.fraction(few.initial_any) + 0.25);
  EXPECT_GE(p80.any.fraction(p80.any.initial_any), few.fraction(few.initial_any) + 0.25);
}

}  // namespace
}  // namespace pb
