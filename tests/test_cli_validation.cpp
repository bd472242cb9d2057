// Validation where data enters, through the binary: a BOP scene whose camera
// matrix has fx = 0 (unchecked, it gives exit 0 and "no hypothesis") or whose
// pose is not a rotation is exit 2 naming the file and the entry, for
// `recognize` and for `run` (before any trial, no results folder); a dataset
// whose scene_gt_info.json lacks bbox_obj (as many converted datasets do)
// is used as it is.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.h"
#include "test_cli_run_scene.h"

namespace fs = std::filesystem;

namespace {

class Validation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new pbcli::TempDir;
    pbcli::write_file(tmp_->path + "/scene.yaml", pbcli::kSmallTableScene);
    const auto g = pbcli::run("generate scene.yaml --out ds", tmp_->path);
    ASSERT_EQ(g.code, 0) << g.err;
  }
  static void TearDownTestSuite() {
    delete tmp_;
    tmp_ = nullptr;
  }
  void SetUp() override {
    fs::remove_all(tmp_->path + "/copy");
    fs::create_directories(tmp_->path + "/copy");
    fs::copy(tmp_->path + "/ds", dir(), fs::copy_options::recursive);
    pbcli::write_file(dir() + "/../exp.yaml",
                      "name: v\nobject: ls5\nscenes:\n  - name: s\n    dataset: " + dir() +
                          "\n    scenario: table\n    images: 1\ndescriptors: [cvfh]\nrefinements: [icp]\n"
                          "settings:\n  views: {views: 4}\n");
  }
  static std::string dir() { return tmp_->path + "/copy/ds"; }
  static std::string scene() { return dir() + "/test/000001"; }
  template <typename F>
  void edit(const std::string& file, F&& f) {
    nlohmann::json j = nlohmann::json::parse(pbcli::slurp(file));
    f(j);
    pbcli::write_file(file, j.dump());
  }
  pbcli::Run recognize() {
    return pbcli::run("recognize --dataset '" + dir() + "' --scene 1 --image 0 --object ls5 --method cvfh --views 4 --cache '" +
                          tmp_->path + "/cache'",
                      tmp_->path);
  }
  pbcli::Run run() {
    return pbcli::run("run '" + dir() + "/../exp.yaml' -q --out '" + dir() + "/../r' --cache '" + tmp_->path +
                          "/cache'",
                      tmp_->path);
  }
  static pbcli::TempDir* tmp_;
};
pbcli::TempDir* Validation::tmp_ = nullptr;

TEST_F(Validation, ZeroFocalLengthIsExit2NamingFileAndEntry) {
  edit(scene() + "/scene_camera.json", [](auto& j) { j["0"]["cam_K"][0] = 0; });
  for (const auto& r : {recognize(), run()}) {
    EXPECT_EQ(r.code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find(scene() + "/scene_camera.json"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("0.cam_K.fx"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir() + "/../r"));
}

TEST_F(Validation, APoseThatIsNotARotationIsExit2) {
  edit(scene() + "/scene_gt.json", [](auto& j) {
    for (auto& v : j["0"][0]["cam_R_m2c"]) v = v.template get<double>() * 2;
  });
  for (const auto& r : {recognize(), run()}) {
    EXPECT_EQ(r.code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find(scene() + "/scene_gt.json"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("0[0].cam_R_m2c"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("not a rotation"), std::string::npos) << r.err;
  }
}

TEST_F(Validation, MissingBboxObjIsNotNeeded) {
  edit(scene() + "/scene_gt_info.json", [](auto& j) {
    for (auto& [id, list] : j.items())
      for (auto& e : list) e.erase("bbox_obj");
  });
  const auto r = recognize();
  EXPECT_EQ(r.code, 0) << r.err;
  const auto w = run();
  ASSERT_EQ(w.code, 0) << w.err;
  const auto rec = nlohmann::json::parse(pbcli::slurp(dir() + "/../r/records.jsonl"));
  EXPECT_NE(rec["status"], "error") << rec.dump();
  EXPECT_TRUE(rec.contains("visib_fract")) << rec.dump();
}

}  // namespace
