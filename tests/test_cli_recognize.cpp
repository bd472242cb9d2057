// posebench recognize on a tiny BOP dataset written by the test (an L-shaped
// block on a table, ray-cast here): the JSON output (status, R, t, score,
// inliers, times, errors), the text output, the overlay PNG, bad input
// (no points, object absent -> exit 0 with status no_hypothesis; unknown
// object or method -> exit 2 naming the field).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/random.h"
#include "io/bop.h"
#include "io/mesh_io.h"
#include "io/png.h"

namespace fs = std::filesystem;

namespace {

pb::Mesh box(pb::Vec3f lo, pb::Vec3f hi) {
  pb::Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  const int f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                        {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (auto& t : f) m.faces.emplace_back(t[0], t[1], t[2]);
  return m;
}

// The L-block of test_recognition_pipeline_util.h, origin at its bbox centre.
pb::Mesh l_block() {
  pb::Mesh m = box({-60, -30, -20}, {60, 30, 20});
  m.append(box({20, -30, 0}, {60, 30, 100}));
  m.append(box({-45, 30, -15}, {-15, 60, 15}));
  const Eigen::AlignedBox3f b = m.bounds();
  pb::Pose C;
  C.t = -b.center().cast<double>();
  m.transform(C);
  return m;
}

// Ray casting (Moeller-Trumbore) of meshes at poses: depth z per pixel.
pb::DepthImage raycast(const pb::Intrinsics& K, const std::vector<std::pair<const pb::Mesh*, pb::Pose>>& items) {
  std::vector<std::array<pb::Vec3, 3>> tris;
  for (const auto& [m, T] : items)
    for (const auto& f : m->faces)
      tris.push_back({T * m->vertices[f[0]].cast<double>(), T * m->vertices[f[1]].cast<double>(),
                      T * m->vertices[f[2]].cast<double>()});
  pb::DepthImage d(K.width, K.height);
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const pb::Vec3 dir = K.backproject(u, v, 1.0);
      double best = 1e30;
      for (const auto& t : tris) {
        const pb::Vec3 e1 = t[1] - t[0], e2 = t[2] - t[0], p = dir.cross(e2);
        const double det = e1.dot(p);
        if (std::abs(det) < 1e-12) continue;
        const pb::Vec3 s = -t[0];
        const double a = s.dot(p) / det;
        if (a < 0 || a > 1) continue;
        const pb::Vec3 q = s.cross(e1);
        const double b = dir.dot(q) / det;
        if (b < 0 || a + b > 1) continue;
        const double z = e2.dot(q) / det;  // ray parameter = depth since dir.z = 1
        if (z > 0 && z < best) best = z;
      }
      if (best < 1e30) d.at(u, v) = static_cast<float>(best);
    }
  return d;
}

pb::Pose look_at(const pb::Vec3& target, double distance, double el_deg, double az_deg) {
  const double el = el_deg * M_PI / 180, az = az_deg * M_PI / 180;
  const pb::Vec3 c = target + distance * pb::Vec3(std::cos(el) * std::sin(az), -std::cos(el) * std::cos(az), std::sin(el));
  const pb::Vec3 z = (target - c).normalized(), x = z.cross(pb::Vec3::UnitZ()).normalized(), y = z.cross(x);
  pb::Pose T;
  T.R.col(0) = x;
  T.R.col(1) = y;
  T.R.col(2) = z;
  T.t = c;
  return T;
}

struct CmdResult {
  int code = -1;
  std::string out;
};

CmdResult run(const std::string& args) {
  const std::string cmd = std::string(POSEBENCH_BINARY) + " " + args + " 2>&1";
  CmdResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return r;
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.out.append(buf, n);
  const int st = pclose(p);
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

class CliRecognize : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = new fs::path(fs::temp_directory_path() / ("pb_cli_reco_" + std::to_string(::getpid())));
    fs::remove_all(*root_);
    fs::create_directories(*root_ / "models");
    const pb::Mesh obj = l_block();
    pb::write_ply((*root_ / "models" / "obj_000001.ply").string(), obj);
    pb::Mesh cyl = box({-20, -20, -110}, {20, 20, 110});  // a tall post, never placed
    pb::write_ply((*root_ / "models" / "obj_000002.ply").string(), cyl);
    // A well-formed model file without geometry: an empty model.
    std::ofstream(*root_ / "models" / "obj_000003.ply")
        << "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
           "element face 0\nproperty list uchar int vertex_indices\nend_header\n";
    std::map<int, pb::ModelInfo> models;
    models[3].obj_id = 3;
    models[3].name = "empty";
    models[3].diameter = 100;  // what models_info claims; the file has no geometry
    models[3].size = pb::Vec3(50, 50, 50);
    for (int id : {1, 2}) {
      const pb::Mesh& m = id == 1 ? obj : cyl;
      pb::ModelInfo info;
      info.obj_id = id;
      info.name = id == 1 ? "l_block" : "post";
      info.diameter = m.diameter();
      const auto b = m.bounds();
      info.min = b.min().cast<double>();
      info.size = (b.max() - b.min()).cast<double>();
      models[id] = info;
    }
    pb::write_models_info((*root_ / "models" / "models_info.json").string(), models);

    const pb::Intrinsics K = pb::Intrinsics::from_fov(240, 180, 50, 50.0 * 180 / 240);
    const pb::Pose T_cam_world = look_at(pb::Vec3(0, 0, 40), 700, 40, 20).inverse();
    const pb::Mesh table = box({-1000, -1000, -20}, {1000, 1000, 0});
    pb::Pose T_world_model;
    T_world_model.R = Eigen::AngleAxisd(30 * M_PI / 180, pb::Vec3::UnitZ()).toRotationMatrix();
    T_world_model.t = pb::Vec3(0, 0, -obj.bounds().min().z());
    gt_ = new pb::Pose(T_cam_world * T_world_model);

    pb::SceneInfo scene;
    scene.scene_id = 1;
    const std::string sdir = (*root_ / "test" / "000001").string();
    fs::create_directories(sdir + "/depth");
    pb::Rng rng(5);
    // A second instance of the block in image 3's ground truth, 250 mm to
    // the side and hidden (not in its depth), listed first.
    hidden_ = new pb::Pose(*gt_);
    hidden_->t.x() += 250;
    for (int im = 0; im < 4; ++im) {
      // 0: the block on the table; 1: the table only; 2: no depth at all;
      // 3: as 0, with the hidden instance listed before the seen one.
      pb::DepthImage d(K.width, K.height);
      if (im == 0 || im == 3) d = raycast(K, {{&table, T_cam_world}, {&obj, *gt_}});
      if (im == 1) d = raycast(K, {{&table, T_cam_world}});
      for (float& z : d.z)
        if (z > 0) z += static_cast<float>(rng.normal(0, 1.0));
      pb::ImageInfo info;
      info.im_id = im;
      info.K = K;
      info.depth_scale = 0.1;
      if (im == 0) info.gt.push_back({1, *gt_});
      if (im == 3) info.gt = {{1, *hidden_}, {1, *gt_}};
      scene.images[im] = info;
      char name[32];
      std::snprintf(name, sizeof name, "/depth/%06d.png", im);
      pb::write_depth_png(sdir + name, d, 0.1);
    }
    pb::write_scene_json(sdir, scene);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*root_);
    delete root_;
    delete gt_;
    delete hidden_;
  }
  static std::string base(int image, const std::string& object = "l_block") {
    return "recognize --dataset " + root_->string() + " --scene 1 --image " + std::to_string(image) + " --object " +
           object + " --views 8 --cache " + (*root_ / "cache").string();
  }
  static fs::path* root_;
  static pb::Pose* gt_;
  static pb::Pose* hidden_;
};
fs::path* CliRecognize::root_ = nullptr;
pb::Pose* CliRecognize::gt_ = nullptr;
pb::Pose* CliRecognize::hidden_ = nullptr;

TEST_F(CliRecognize, JsonHasPoseInliersTimesAndErrors) {
  const CmdResult r = run(base(0) + " --method fpfh --refine icp --json --overlay " + (*root_ / "overlay.png").string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["status"], "ok") << r.out;
  ASSERT_EQ(j["R"].size(), 9u);
  ASSERT_EQ(j["t"].size(), 3u);
  EXPECT_GT(j["inliers"].get<int>(), 0);
  EXPECT_TRUE(j.contains("score"));
  for (const char* stage : {"preprocess", "describe", "match", "group", "initial_pose", "refine", "verify", "total"})
    EXPECT_GE(j["times"][stage].get<double>(), 0.0) << stage;
  EXPECT_GT(j["times"]["total"].get<double>(), 0.0);
  // The pose against the ground truth written into the dataset.
  pb::Mat3 R;
  for (int k = 0; k < 9; ++k) R(k / 3, k % 3) = j["R"][k].get<double>();
  const pb::Vec3 t(j["t"][0].get<double>(), j["t"][1].get<double>(), j["t"][2].get<double>());
  EXPECT_LT((t - gt_->t).norm(), 10.0);
  EXPECT_GT(((R.transpose() * gt_->R).trace() - 1) / 2, std::cos(5 * M_PI / 180));
  // ... and the errors the command computed agree.
  ASSERT_TRUE(j.contains("errors")) << r.out;
  EXPECT_NEAR(j["errors"]["translation_mm"].get<double>(), (t - gt_->t).norm(), 1e-6);
  EXPECT_LT(j["errors"]["rotation_deg"].get<double>(), 5.0);
  EXPECT_LT(j["errors"]["rotation"].get<double>(), 0.01);
  EXPECT_TRUE(j["errors"]["correct"].get<bool>());
  // The overlay is a PNG of the image's size.
  const pb::PngHeader h = pb::read_png_header((*root_ / "overlay.png").string());
  EXPECT_EQ(h.width, 240);
  EXPECT_EQ(h.height, 180);
  EXPECT_EQ(h.channels, 3);
  // A second run reuses the training cache and prints the same pose.
  const CmdResult again = run(base(0) + " --method fpfh --refine icp --json");
  ASSERT_EQ(again.code, 0) << again.out;
  const auto j2 = nlohmann::json::parse(again.out);
  EXPECT_TRUE(j2["train"]["from_cache"].get<bool>());
  EXPECT_EQ(j2["R"], j["R"]);
  EXPECT_EQ(j2["t"], j["t"]);
}

// One judge (eval/judge.h): with two instances of the object in the image,
// `run` and `recognize` judge the same estimate against the instance it fits
// (the seen one, listed second), not the first listed, and agree on the
// errors and on correct.
TEST_F(CliRecognize, RunAndRecognizeJudgeTwoInstancesTheSameWay) {
  const fs::path dir = *root_ / "judge";
  fs::create_directories(dir);
  std::ofstream(dir / "targets.json") << R"([{"im_id": 3, "inst_count": 1, "obj_id": 1, "scene_id": 1}])";
  std::ofstream(dir / "exp.yaml") << "object: l_block\nscenes:\n  - name: s\n    dataset: " << root_->string()
                                   << "\n    targets: " << (dir / "targets.json").string()
                                   << "\n    scene_ids: [1]\ndescriptors: [fpfh]\nrefinements: [icp]\n"
                                      "settings: {views: {views: 8}}\n";
  const CmdResult ran = run("run " + (dir / "exp.yaml").string() + " --jobs 1 -q --out " + (dir / "out").string() +
                            " --cache " + (*root_ / "cache").string());
  ASSERT_EQ(ran.code, 0) << ran.out;
  std::ifstream in(dir / "out" / "records.jsonl");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  const auto rec = nlohmann::json::parse(line);
  ASSERT_EQ(rec["status"], "ok") << line;
  EXPECT_TRUE(rec["correct"].get<bool>()) << line;
  const pb::Vec3 rec_gt(rec["gt"]["t"][0].get<double>(), rec["gt"]["t"][1].get<double>(), rec["gt"]["t"][2].get<double>());
  EXPECT_LT((rec_gt - gt_->t).norm(), 1e-6) << "the record names the seen instance";
  EXPECT_LT(rec["errors"]["translation_mm"].get<double>(), 10.0);

  const CmdResult r = run(base(3) + " --method fpfh --refine icp --json --seed " + std::to_string(rec["seed"].get<uint64_t>()));
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["status"], "ok") << r.out;
  EXPECT_EQ(j["ground_truth_instances"], 2);
  EXPECT_TRUE(j["errors"]["correct"].get<bool>()) << r.out;
  // Both errors are against the seen instance.
  const auto t_of = [](const nlohmann::json& t) {
    return pb::Vec3(t[0].get<double>(), t[1].get<double>(), t[2].get<double>());
  };
  EXPECT_NEAR(j["errors"]["translation_mm"].get<double>(), (t_of(j["t"]) - gt_->t).norm(), 1e-6);
  EXPECT_NEAR(rec["errors"]["translation_mm"].get<double>(), (t_of(rec["estimate"]["t"]) - gt_->t).norm(), 1e-6);
  // One resolution of relative lengths (resolve_for_scene: the models_info
  // diameter, the sensor's floor at the scene's first image, not this one):
  // the same settings and so the same pose, bit for bit.
  EXPECT_EQ(j["R"], rec["estimate"]["R"]);
  EXPECT_EQ(j["t"], rec["estimate"]["t"]);
  EXPECT_EQ(j["errors"]["translation_mm"], rec["errors"]["translation_mm"]);
}

// --explain: every ranked hypothesis with its errors, and the ground truth
// refined and verified as one more. Verified on the merged model cloud, so
// that every pose is counted on the same points (with the default, each on
// its own training view's cloud, a pose's count also depends on the view's
// size). On this clean image the chosen pose is the truth: the first ranked
// one has the chosen pose's errors, and the refined ground truth verifies
// within a few percent of it: only poses at the truth rank above it.
TEST_F(CliRecognize, ExplainRanksTheHypothesesAndTheGroundTruth) {
  const std::string cfg = (*root_ / "merged.yaml").string();
  std::ofstream(cfg) << "verify:\n  inlier_model: merged\n";
  const CmdResult r = run(base(0) + " --method fpfh --refine icp --json --explain --config " + cfg);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["status"], "ok") << r.out;
  ASSERT_TRUE(j["errors"]["correct"].get<bool>()) << r.out;
  ASSERT_EQ(j["ranked"].size(), j["hypotheses"].get<size_t>());
  ASSERT_GE(j["ranked"].size(), 1u);
  const auto& first = j["ranked"][0];
  EXPECT_EQ(first["R"], j["R"]);
  EXPECT_EQ(first["t"], j["t"]);
  EXPECT_NEAR(first["errors"]["translation_mm"].get<double>(), j["errors"]["translation_mm"].get<double>(), 1e-9);
  for (size_t i = 1; i < j["ranked"].size(); ++i)
    EXPECT_LE(j["ranked"][i]["verification"].get<double>(), j["ranked"][i - 1]["verification"].get<double>()) << i;
  const auto& g = j["ground_truth_refined"];
  const int above = g["would_rank"].get<int>();
  ASSERT_LE(above, static_cast<int>(j["ranked"].size()));
  for (int i = 0; i < above; ++i) EXPECT_LT(j["ranked"][i]["errors"]["translation_mm"].get<double>(), 5.0) << i;
  EXPECT_NEAR(g["verification"].get<double>(), first["verification"].get<double>(),
              0.05 * first["verification"].get<double>());
  const pb::Vec3 t(g["t"][0].get<double>(), g["t"][1].get<double>(), g["t"][2].get<double>());
  EXPECT_LT((t - gt_->t).norm(), 10.0);
  // The text form prints the same list.
  const CmdResult text = run(base(0) + " --method fpfh --refine icp --explain --config " + cfg);
  ASSERT_EQ(text.code, 0) << text.out;
  for (const char* s : {"ranked hypotheses", "  0: ", "ground truth refined and verified: verification", "would rank"})
    EXPECT_NE(text.out.find(s), std::string::npos) << s << " missing in:\n" << text.out;
}

TEST_F(CliRecognize, TextOutputNamesPoseTimesAndErrors) {
  const CmdResult r = run(base(0, "1") + " --method fpfh --refine icp");
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* s : {"status: ok", "pose T_cam_model", "inliers:", "times (s): preprocess", "errors vs ground truth",
                        "correct"})
    EXPECT_NE(r.out.find(s), std::string::npos) << s << " missing in:\n" << r.out;
}

TEST_F(CliRecognize, NoPointsAndAbsentObjectExitZeroWithNoHypothesis) {
  for (int im : {1, 2}) {
    const CmdResult r = run(base(im) + " --method fpfh --refine icp --json");
    ASSERT_EQ(r.code, 0) << r.out;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["status"], "no_hypothesis") << r.out;
    EXPECT_TRUE(j["R"].is_null());
    EXPECT_FALSE(j["message"].get<std::string>().empty());
    EXPECT_FALSE(j.contains("errors"));
  }
  // An object that is in the dataset but not in the image, with a minimum
  // inlier fraction: the L-block cannot be explained by the "post" model's views.
  const std::string cfg = (*root_ / "strict.yaml").string();
  std::ofstream(cfg) << "verify:\n  min_inlier_fraction: 0.6\n";
  const CmdResult r = run(base(0, "post") + " --method fpfh --json --config " + cfg);
  ASSERT_EQ(r.code, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "no_hypothesis") << r.out;
  EXPECT_EQ(j["ground_truth_instances"], 0);
  // An empty model.
  const CmdResult e = run(base(0, "empty") + " --method fpfh --json");
  ASSERT_EQ(e.code, 0) << e.out;
  const auto je = nlohmann::json::parse(e.out);
  EXPECT_EQ(je["status"], "no_hypothesis") << e.out;
  EXPECT_NE(je["message"].get<std::string>().find("empty model"), std::string::npos) << e.out;
}

TEST_F(CliRecognize, BadInputExitsTwoNamingTheField) {
  CmdResult r = run(base(0, "teapot") + " --method fpfh");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("models_info.json"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("unknown object 'teapot'"), std::string::npos) << r.out;
  r = run(base(0) + " --method sift");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--method"), std::string::npos) << r.out;
  r = run(base(7) + " --method fpfh");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("no image 7"), std::string::npos) << r.out;
  const std::string cfg = (*root_ / "bad.yaml").string();
  std::ofstream(cfg) << "preprocess:\n  voxel_size: 5\n";
  r = run(base(0) + " --config " + cfg);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("bad.yaml"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("preprocess.voxel_size"), std::string::npos) << r.out;
  // A broken model file stays an input error.
  fs::copy_file(*root_ / "models" / "obj_000002.ply", *root_ / "models" / "obj_000002.ply.bak",
                fs::copy_options::overwrite_existing);
  // (Not a truncated PLY header: assimp 5.2 never returns on one.)
  std::ofstream(*root_ / "models" / "obj_000002.ply", std::ios::trunc) << "this is not a mesh\n";
  r = run(base(0, "post") + " --method fpfh");
  fs::copy_file(*root_ / "models" / "obj_000002.ply.bak", *root_ / "models" / "obj_000002.ply",
                fs::copy_options::overwrite_existing);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("obj_000002.ply"), std::string::npos) << r.out;
  r = run("recognize --dataset /nonexistent/x --scene 1 --image 0 --object 1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("/nonexistent/x"), std::string::npos) << r.out;
}

}  // namespace
