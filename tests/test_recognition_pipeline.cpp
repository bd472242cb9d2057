// The recognition pipeline end to end on small rendered table scenes:
// determinism (same pose bit for bit with 1 and 2 threads, for every
// descriptor), bad input (no points, object absent, empty model -> status
// no_hypothesis, never a throw), and the training cache (reuse, identical
// results, corrupt files rebuilt).
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "recognition/pipeline.h"
#include "recognition_train_util.h"
#include "test_recognition_pipeline_util.h"

namespace fs = std::filesystem;

namespace {

// Small, fast settings: 8 training views at 128 px.
pb::RecognitionSettings small_settings(const std::string& descriptor, const std::string& refinement = "icp") {
  pb::RecognitionSettings s;
  s.descriptor = descriptor;
  s.refinement = refinement;
  s.views.views = 8;
  s.views.resolution = 128;
  s.relative.clear();  // the stage headers' mm values (the L block is about as large as the thesis's objects)
  return s;
}

class Pipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    mesh_ = new pb::Mesh(pbtest::make_l_block());
    scene_ = new pbtest::TableScene(pbtest::render_table_scene(*mesh_));
  }
  static void TearDownTestSuite() {
    delete scene_;
    delete mesh_;
  }
  // The model trained for `s`, and in *all the result of refining every
  // hypothesis ("ok" expected): the max_hypotheses tests' reference.
  static auto trained_and_all_refined(const pb::RecognitionSettings& s, pb::RecognitionResult* all) {
    auto model = pb::test::train(*mesh_, s);
    *all = pb::recognize(scene_->depth, scene_->K, *model, s);
    EXPECT_EQ(all->status, "ok") << all->message;
    return model;
  }
  static pb::Mesh* mesh_;
  static pbtest::TableScene* scene_;
};
pb::Mesh* Pipeline::mesh_ = nullptr;
pbtest::TableScene* Pipeline::scene_ = nullptr;

bool same_bits(const pb::Pose& a, const pb::Pose& b) {
  return std::memcmp(a.R.data(), b.R.data(), 9 * sizeof(double)) == 0 &&
         std::memcmp(a.t.data(), b.t.data(), 3 * sizeof(double)) == 0;
}

void expect_same_result(const pb::RecognitionResult& a, const pb::RecognitionResult& b, const std::string& what) {
  EXPECT_EQ(a.status, b.status) << what;
  EXPECT_TRUE(same_bits(a.T_cam_model, b.T_cam_model)) << what;
  EXPECT_EQ(a.inliers, b.inliers) << what;
  EXPECT_EQ(std::memcmp(&a.score, &b.score, sizeof(double)), 0) << what;
  ASSERT_EQ(a.hypotheses.size(), b.hypotheses.size()) << what;
  for (size_t i = 0; i < a.hypotheses.size(); ++i) {
    EXPECT_TRUE(same_bits(a.hypotheses[i].T_cam_model, b.hypotheses[i].T_cam_model)) << what << " hypothesis " << i;
    EXPECT_EQ(a.hypotheses[i].inliers, b.hypotheses[i].inliers) << what << " hypothesis " << i;
    EXPECT_EQ(a.hypotheses[i].view, b.hypotheses[i].view) << what << " hypothesis " << i;
  }
}

pb::RecognitionResult run_with_threads(int threads, const pbtest::TableScene& sc, const pb::TrainedModel& m,
                                       pb::RecognitionSettings s) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  s.local.threads = threads;
  pb::RecognitionResult r = pb::recognize(sc.depth, sc.K, m, s);
  omp_set_num_threads(saved);
  return r;
}

class PipelineDeterminism : public Pipeline, public ::testing::WithParamInterface<std::string> {};

TEST_P(PipelineDeterminism, SamePoseBitForBitWithOneAndTwoThreads) {
  const pb::RecognitionSettings s = small_settings(GetParam());
  const auto model = pb::test::train(*mesh_, s);
  const pb::RecognitionResult a = run_with_threads(1, *scene_, *model, s);
  const pb::RecognitionResult b = run_with_threads(2, *scene_, *model, s);
  const pb::RecognitionResult c = run_with_threads(1, *scene_, *model, s);
  expect_same_result(a, b, GetParam() + ": 1 vs 2 threads");
  expect_same_result(a, c, GetParam() + ": repeated");
  // Training is deterministic too: a second model gives the same result.
  const auto model2 = pb::test::train(*mesh_, s);
  expect_same_result(a, run_with_threads(2, *scene_, *model2, s), GetParam() + ": retrained");
  // The call reports its stages.
  EXPECT_GT(a.times.preprocess, 0.0);
  if (a.status == "ok") {
    EXPECT_GT(a.inliers, 0);
    EXPECT_GT(a.times.verify, 0.0);
    EXPECT_EQ(a.inliers, a.hypotheses.front().inliers);
    for (size_t i = 1; i < a.hypotheses.size(); ++i)
      EXPECT_GE(a.hypotheses[i - 1].verification, a.hypotheses[i].verification) << "hypotheses ranked by verify.score";
  }
}

INSTANTIATE_TEST_SUITE_P(EveryDescriptor, PipelineDeterminism,
                         ::testing::Values("fpfh", "shot", "cvfh", "esf", "cesf", "ourcvfh", "ppf"),
                         [](const auto& info) { return info.param; });

TEST_F(Pipeline, FindsTheLBlockWithFpfhAndIcp) {
  const pb::RecognitionSettings s = small_settings("fpfh");
  const auto model = pb::test::train(*mesh_, s);
  const pb::RecognitionResult r = pb::recognize(scene_->depth, scene_->K, *model, s);
  ASSERT_EQ(r.status, "ok") << r.message;
  EXPECT_LT((r.T_cam_model.t - scene_->T_cam_model.t).norm(), 10.0);
  EXPECT_LT(pbtest::angle_deg(r.T_cam_model.R, scene_->T_cam_model.R), 5.0);
}

// refine.max_hypotheses: only that many hypotheses are refined, each exactly
// as in the run that refines all of them (its own random stream: ICP on a
// seeded subset of model points), and here the best is among them, so the
// answer is the same pose bit for bit.
TEST_F(Pipeline, MaxHypothesesRefinesTheMostPromisingExactlyAsBefore) {
  pb::RecognitionSettings s = small_settings("fpfh");
  s.refine.icp.sample_points = 150;
  pb::RecognitionResult all;
  const auto model = trained_and_all_refined(s, &all);
  ASSERT_GT(all.hypotheses.size(), 3u) << all.message;
  s.refine.max_hypotheses = 3;
  const pb::RecognitionResult few = pb::recognize(scene_->depth, scene_->K, *model, s);
  ASSERT_EQ(few.status, "ok") << few.message;
  ASSERT_EQ(few.hypotheses.size(), 3u);
  for (const pb::Hypothesis& h : few.hypotheses) {
    bool found = false;
    for (const pb::Hypothesis& g : all.hypotheses) found = found || same_bits(h.T_cam_model, g.T_cam_model);
    EXPECT_TRUE(found) << "a kept hypothesis is refined as in the full run";
  }
  EXPECT_TRUE(same_bits(few.T_cam_model, all.T_cam_model));
  EXPECT_EQ(few.inliers, all.inliers);
  EXPECT_LT((few.T_cam_model.t - scene_->T_cam_model.t).norm(), 10.0);
}

// refine.screen_points: every hypothesis is registered on a random 60 of its
// model points, the 3 verification ranks first are refined on all of them
// from there. The object is found, the same pose bit for bit with 1 and 2
// threads, and the screening counts: without it (ranked at the initial pose)
// the kept hypotheses are others or refined from elsewhere.
TEST_F(Pipeline, ScreeningOnASubsetKeepsTheBestAndIsDeterministic) {
  pb::RecognitionSettings s = small_settings("fpfh");
  pb::RecognitionResult all;
  const auto model = trained_and_all_refined(s, &all);
  ASSERT_GT(all.hypotheses.size(), 3u) << all.message;
  s.refine.max_hypotheses = 3;
  const pb::RecognitionResult unscreened = pb::recognize(scene_->depth, scene_->K, *model, s);
  ASSERT_EQ(unscreened.hypotheses.size(), 3u);
  s.refine.screen_points = 60;
  const pb::RecognitionResult a = run_with_threads(1, *scene_, *model, s);
  ASSERT_EQ(a.status, "ok") << a.message;
  ASSERT_EQ(a.hypotheses.size(), 3u);
  EXPECT_LT((a.T_cam_model.t - scene_->T_cam_model.t).norm(), 10.0);
  EXPECT_LT(pbtest::angle_deg(a.T_cam_model.R, scene_->T_cam_model.R), 5.0);
  expect_same_result(a, run_with_threads(2, *scene_, *model, s), "screened: 1 vs 2 threads");
  bool differs = false;
  for (size_t i = 0; i < 3; ++i)
    differs = differs || !same_bits(a.hypotheses[i].T_cam_model, unscreened.hypotheses[i].T_cam_model);
  EXPECT_TRUE(differs) << "screening changed nothing";
}

// Registration alone (Table 4.9): from a slightly perturbed ground truth the
// pose is found ("ok", inliers); from a pose 1 m away from the object no
// model point has a scene point within the inlier threshold, and that is
// "no_hypothesis" with the reason, not "ok" with 0 inliers.
TEST_F(Pipeline, RefineFromIsOkOnlyWithInliers) {
  const pb::RecognitionSettings s = small_settings("fpfh");
  const auto model = pb::test::train(*mesh_, s);
  pb::Pose near = scene_->T_cam_model;
  near.t += pb::Vec3(5, -3, 4);
  const pb::RecognitionResult ok = pb::refine_from(scene_->depth, scene_->K, *model, s, near);
  EXPECT_EQ(ok.status, "ok") << ok.message;
  EXPECT_GT(ok.inliers, 0);
  EXPECT_LT((ok.T_cam_model.t - scene_->T_cam_model.t).norm(), 10.0);
  pb::Pose far = scene_->T_cam_model;
  far.t += pb::Vec3(1000, 0, 0);
  const pb::RecognitionResult none = pb::refine_from(scene_->depth, scene_->K, *model, s, far);
  EXPECT_EQ(none.status, "no_hypothesis");
  EXPECT_EQ(none.inliers, 0);
  EXPECT_NE(none.message.find("no hypothesis has an inlier"), std::string::npos) << none.message;
}

TEST_F(Pipeline, NoPointsAfterFilteringIsNoHypothesis) {
  const pb::RecognitionSettings s = small_settings("fpfh");
  const auto model = pb::test::train(*mesh_, s);
  // An image without any depth.
  pb::DepthImage empty(scene_->K.width, scene_->K.height);
  pb::RecognitionResult r = pb::recognize(empty, scene_->K, *model, s);
  EXPECT_EQ(r.status, "no_hypothesis");
  EXPECT_NE(r.message.find("no scene points after filtering"), std::string::npos) << r.message;
  EXPECT_TRUE(r.hypotheses.empty());
  // Everything beyond the range cut.
  pb::DepthImage far = scene_->depth;
  for (float& z : far.z)
    if (z > 0) z += 4000;
  r = pb::recognize(far, scene_->K, *model, s);
  EXPECT_EQ(r.status, "no_hypothesis");
  EXPECT_NE(r.message.find("no scene points after filtering"), std::string::npos) << r.message;
}

TEST_F(Pipeline, ObjectAbsentIsNoHypothesis) {
  for (const std::string d : {"fpfh", "cesf"}) {
    pb::RecognitionSettings s = small_settings(d);
    const auto model = pb::test::train(*mesh_, s);
    // Only the table: nothing is left once the plane is removed.
    pbtest::TableSceneOptions o;
    o.object = false;
    const auto table = pbtest::render_table_scene(*mesh_, o);
    pb::RecognitionResult r = pb::recognize(table.depth, table.K, *model, s);
    EXPECT_EQ(r.status, "no_hypothesis") << d;
    EXPECT_FALSE(r.message.empty());
    // The table and a cylinder, no L-block: the thesis's rule (most inliers
    // wins) may accept a wrong pose; with a minimum inlier fraction the
    // cylinder cannot explain the L-block's views.
    o.distractor = true;
    const auto distractor = pbtest::render_table_scene(*mesh_, o);
    s.verify.min_inlier_fraction = 0.5;
    r = pb::recognize(distractor.depth, distractor.K, *model, s);
    EXPECT_EQ(r.status, "no_hypothesis") << d << ": " << r.inliers << " inliers";
    EXPECT_FALSE(r.message.empty());
    // ... while the same settings accept the L-block when it is there.
    o.object = true;
    const auto both = pbtest::render_table_scene(*mesh_, o);
    r = pb::recognize(both.depth, both.K, *model, s);
    if (d == "fpfh") EXPECT_EQ(r.status, "ok") << r.message;
  }
}

// Tiny and degenerate scenes: whatever survives preprocessing, every
// descriptor returns a result (ok or no_hypothesis) and never throws.
class PipelineTinyScenes : public Pipeline, public ::testing::WithParamInterface<std::string> {};

TEST_P(PipelineTinyScenes, NeverThrow) {
  const pb::RecognitionSettings s = small_settings(GetParam());
  const auto model = pb::test::train(*mesh_, s);
  const pb::Intrinsics& K = scene_->K;
  std::vector<std::pair<std::string, pb::DepthImage>> scenes;
  auto patch = [&](pb::DepthImage& d, int u0, int v0, int w, int h, float z, float slope) {
    for (int v = v0; v < v0 + h; ++v)
      for (int u = u0; u < u0 + w; ++u) d.at(u, v) = z + slope * static_cast<float>(u - u0);
  };
  pb::DepthImage d(K.width, K.height);
  patch(d, 150, 110, 2, 2, 800, 0);
  scenes.emplace_back("2x2 pixels", d);
  d = pb::DepthImage(K.width, K.height);
  patch(d, 150, 110, 12, 12, 800, 0);
  scenes.emplace_back("a 30 mm flat patch", d);
  d = pb::DepthImage(K.width, K.height);
  patch(d, 100, 50, 1, 120, 700, 0);
  scenes.emplace_back("a line", d);
  d = pb::DepthImage(K.width, K.height);
  for (int k = 0; k < 6; ++k) patch(d, 20 + 45 * k, 30 + 30 * k, 6, 6, 600 + 50 * k, 2);
  scenes.emplace_back("scattered small patches", d);
  d = pb::DepthImage(K.width, K.height);
  patch(d, 0, 0, K.width, K.height, 900, 0);
  scenes.emplace_back("a wall filling the image", d);
  for (const auto& [name, depth] : scenes) {
    pb::RecognitionResult r;
    EXPECT_NO_THROW(r = pb::recognize(depth, K, *model, s)) << GetParam() << ": " << name;
    EXPECT_TRUE(r.status == "ok" || r.status == "no_hypothesis") << r.status;
    if (r.status == "no_hypothesis") EXPECT_FALSE(r.message.empty()) << name;
  }
}

INSTANTIATE_TEST_SUITE_P(EveryDescriptor, PipelineTinyScenes,
                         ::testing::Values("fpfh", "shot", "cvfh", "esf", "cesf", "ourcvfh", "ppf"),
                         [](const auto& info) { return info.param; });

TEST_F(Pipeline, EmptyModelIsNoHypothesis) {
  for (const std::string d : {"fpfh", "esf", "ppf"}) {
    const pb::RecognitionSettings s = small_settings(d);
    bool cached = true;
    const auto model = pb::test::train(pb::Mesh{}, s, {}, &cached);
    EXPECT_FALSE(cached);
    EXPECT_TRUE(pb::trained_model_info(*model).empty);
    const pb::RecognitionResult r = pb::recognize(scene_->depth, scene_->K, *model, s);
    EXPECT_EQ(r.status, "no_hypothesis") << d;
    EXPECT_NE(r.message.find("empty model"), std::string::npos) << r.message;
  }
  // A degenerate mesh (all vertices in one point) renders nothing.
  pb::Mesh dot;
  dot.vertices = {pb::Vec3f(0, 0, 0), pb::Vec3f(0, 0, 0), pb::Vec3f(0, 0, 0)};
  dot.faces = {Eigen::Vector3i(0, 1, 2)};
  const pb::RecognitionSettings s = small_settings("fpfh");
  const auto model = pb::test::train(dot, s);
  const pb::RecognitionResult r = pb::recognize(scene_->depth, scene_->K, *model, s);
  EXPECT_EQ(r.status, "no_hypothesis");
  EXPECT_NE(r.message.find("empty model"), std::string::npos) << r.message;
}

TEST_F(Pipeline, MismatchedSettingsAreInputErrors) {
  const pb::RecognitionSettings s = small_settings("fpfh");
  const auto model = pb::test::train(*mesh_, s);
  pb::RecognitionSettings other = s;
  other.descriptor = "shot";
  EXPECT_THROW(pb::recognize(scene_->depth, scene_->K, *model, other), pb::InputError);
  other = s;
  other.refinement = "icp9";
  EXPECT_THROW(pb::recognize(scene_->depth, scene_->K, *model, other), pb::InputError);
  pb::Intrinsics K = scene_->K;
  K.width += 1;
  EXPECT_THROW(pb::recognize(scene_->depth, K, *model, s), pb::InputError);
  EXPECT_THROW(pb::test::train(*mesh_, small_settings("sift")), pb::InputError);
}

fs::path fresh_cache_dir(const std::string& tag) {
  const fs::path dir = fs::temp_directory_path() / ("pb_reco_cache_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir;
}

// Every method's trained state goes through its save / load: a model read
// back from the cache gives the same hypotheses bit for bit.
class PipelineCache : public Pipeline, public ::testing::WithParamInterface<std::string> {};

TEST_P(PipelineCache, SecondTrainingComesFromTheCacheWithIdenticalResults) {
  const fs::path dir = fresh_cache_dir(GetParam());
  pb::TrainOptions opt;
  opt.cache_dir = dir.string();
  const std::string name = "l block";
  const pb::RecognitionSettings s = small_settings(GetParam());
  bool cached = true;
  const auto fresh = pb::test::train(*mesh_, s, opt, &cached, name);
  EXPECT_FALSE(cached);
  const std::string file = pb::trained_model_info(*fresh).cache_file;
  ASSERT_TRUE(fs::exists(file)) << file;
  const auto again = pb::test::train(*mesh_, s, opt, &cached, name);
  EXPECT_TRUE(cached);
  EXPECT_EQ(pb::trained_model_info(*again).views, pb::trained_model_info(*fresh).views);
  EXPECT_EQ(pb::trained_model_info(*again).view_points, pb::trained_model_info(*fresh).view_points);
  expect_same_result(pb::recognize(scene_->depth, scene_->K, *fresh, s),
                     pb::recognize(scene_->depth, scene_->K, *again, s), GetParam() + ": fresh vs cached model");
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(EveryDescriptor, PipelineCache,
                         ::testing::Values("fpfh", "shot", "cvfh", "esf", "cesf", "ourcvfh", "ppf"),
                         [](const auto& info) { return info.param; });

TEST_F(Pipeline, CacheKeyAndCorruptFiles) {
  const fs::path dir = fresh_cache_dir("key");
  pb::TrainOptions opt;
  opt.cache_dir = (dir / "sub" / "dir").string();  // created on demand
  const std::string name = "l/block";  // sanitized in the file name
  const pb::RecognitionSettings s = small_settings("fpfh");
  bool cached = true;
  const auto fresh = pb::test::train(*mesh_, s, opt, &cached, name);
  EXPECT_FALSE(cached);
  const std::string file = pb::trained_model_info(*fresh).cache_file;
  ASSERT_TRUE(fs::exists(file)) << file;
  EXPECT_EQ(fs::path(file).parent_path(), fs::path(opt.cache_dir));
  const auto r1 = pb::recognize(scene_->depth, scene_->K, *fresh, s);

  // A setting that changes training changes the key (a new file) ...
  pb::RecognitionSettings s2 = s;
  s2.preprocess.voxel_mm = 8;
  pb::test::train(*mesh_, s2, opt, &cached, name);
  EXPECT_FALSE(cached);
  s2 = s;
  s2.views.views = 6;
  pb::test::train(*mesh_, s2, opt, &cached, name);
  EXPECT_FALSE(cached);
  // ... one that does not (refinement, verification, thread count) reuses it.
  s2 = s;
  s2.refinement = "icp_plane";
  s2.refine.max_iterations = 10;
  s2.verify.inlier_threshold_mm = 7;
  s2.local.threads = 1;
  pb::test::train(*mesh_, s2, opt, &cached, name);
  EXPECT_TRUE(cached);
  // Another method's section does not touch this method's key: FPFH reads
  // only `local` (and preprocess, the views, the seed).
  s2 = s;
  s2.ppf.model_points = 123;
  s2.global.top_k = 9;
  pb::test::train(*mesh_, s2, opt, &cached, name);
  EXPECT_TRUE(cached);
  // Its own section does.
  s2 = s;
  s2.local.keypoint_voxel_mm = 21;
  pb::test::train(*mesh_, s2, opt, &cached, name);
  EXPECT_FALSE(cached);
  // A different mesh is a different key.
  pb::Mesh scaled = *mesh_;
  for (auto& v : scaled.vertices) v *= 1.1f;
  pb::test::train(scaled, s, opt, &cached, name);
  EXPECT_FALSE(cached);

  // Corrupt files are ignored and rebuilt: truncated, a flipped byte, garbage.
  const auto size = fs::file_size(file);
  fs::resize_file(file, size / 2);
  const auto rebuilt = pb::test::train(*mesh_, s, opt, &cached, name);
  EXPECT_FALSE(cached);
  EXPECT_EQ(fs::file_size(file), size);
  expect_same_result(r1, pb::recognize(scene_->depth, scene_->K, *rebuilt, s), "rebuilt model");
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(size - 5));
    char c = 0;
    f.get(c);
    f.seekp(static_cast<std::streamoff>(size - 5));
    f.put(static_cast<char>(c ^ 0x5a));
  }
  pb::test::train(*mesh_, s, opt, &cached, name);
  EXPECT_FALSE(cached);
  std::ofstream(file, std::ios::binary | std::ios::trunc) << "not a cache file";
  pb::test::train(*mesh_, s, opt, &cached, name);
  EXPECT_FALSE(cached);
  pb::test::train(*mesh_, s, opt, &cached, name);
  EXPECT_TRUE(cached);
  // No temporary files are left behind: cache files, and beside each the
  // lock its trainer held (kept: removing a lock file others may wait on
  // would let two processes hold "the" lock).
  for (const auto& e : fs::directory_iterator(opt.cache_dir)) {
    const std::string p = e.path().string();
    if (e.path().extension() == ".lock")
      EXPECT_TRUE(fs::exists(p.substr(0, p.size() - 5))) << p;
    else
      EXPECT_EQ(e.path().extension(), ".bin") << p;
  }
  // An unwritable cache location is an input error naming it.
  const fs::path blocker = dir / "a_file";
  std::ofstream(blocker) << "x";
  opt.cache_dir = (blocker / "cache").string();
  EXPECT_THROW(pb::test::train(*mesh_, s, opt, nullptr, name), pb::InputError);
  fs::remove_all(dir);
}

}  // namespace
