// posebench run: resume after a kill loses and duplicates nothing, results
// do not depend on --jobs, and bad input is exit 2 with a clear message that
// leaves existing results untouched.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli_test_util.h"
#include "test_cli_run_scene.h"

namespace fs = std::filesystem;

namespace {

std::string experiment_yaml(const std::string& scene_cfg) {
  return "name: runtest\nseed: 3\nobject: ls5\nscenes:\n  - name: table_small\n    generate: " + scene_cfg +
         "\n    scenario: table\ndescriptors: [cvfh, fpfh]\nrefinements: [icp]\n"
         "added_noise_mm: [0, 3]\nsettings:\n  views: {views: 4}\n";
}

std::map<std::string, nlohmann::json> comparable(const std::string& dir) {
  return pbcli::records_by_key(dir + "/records.jsonl");
}

class RunTest : public ::testing::Test {
 protected:
  void SetUp() override {
    pbcli::write_file(tmp.path + "/scene.yaml", pbcli::kSmallTableScene);
    pbcli::write_file(tmp.path + "/exp.yaml", experiment_yaml(tmp.path + "/scene.yaml"));
  }
  pbcli::TempDir tmp;
  std::string common() const { return "--cache '" + tmp.path + "/cache' --scenes '" + tmp.path + "/scenes' -q"; }
};

TEST_F(RunTest, ResultsDoNotDependOnJobsAndResumeAfterKillLosesNothing) {
  // Reference: one uninterrupted run with one worker.
  auto a = pbcli::run("run exp.yaml --out r1 --jobs 1 " + common(), tmp.path);
  ASSERT_EQ(a.code, 0) << a.err;
  const auto r1 = comparable(tmp.path + "/r1");
  ASSERT_EQ(r1.size(), 3u * 2u * 2u);  // images x descriptors x noise levels
  int ok = 0;
  for (const auto& [k, v] : r1) ok += v["status"] == "ok";
  EXPECT_GT(ok, 0);

  // Two workers: the same records (up to timing fields).
  auto b = pbcli::run("run exp.yaml --out r2 --jobs 2 " + common(), tmp.path);
  ASSERT_EQ(b.code, 0) << b.err;
  EXPECT_EQ(comparable(tmp.path + "/r2"), r1);

  // Killed mid-way, then resumed: the same records, none lost or duplicated.
  const pid_t pid = fork();
  if (pid == 0) {
    ASSERT_EQ(chdir(tmp.path.c_str()), 0);
    const std::string cache = tmp.path + "/cache", scenes = tmp.path + "/scenes";
    execl(POSEBENCH_BINARY, POSEBENCH_BINARY, "run", "exp.yaml", "--out", "r3", "--jobs", "1", "--cache",
          cache.c_str(), "--scenes", scenes.c_str(), "-q", static_cast<char*>(nullptr));
    _exit(127);
  }
  const std::string rec3 = tmp.path + "/r3/records.jsonl";
  for (int i = 0; i < 600; ++i) {  // wait for some, not all, records
    const std::string text = pbcli::slurp(rec3);
    if (std::count(text.begin(), text.end(), '\n') >= 3) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  kill(pid, SIGKILL);
  waitpid(pid, nullptr, 0);
  const size_t partial = comparable(tmp.path + "/r3").size();
  EXPECT_GE(partial, 1u);
  EXPECT_LT(partial, r1.size()) << "the run finished before it could be killed";
  auto c = pbcli::run("run exp.yaml --out r3 --jobs 1 " + common(), tmp.path);
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.out.find("already recorded"), std::string::npos) << c.out;
  EXPECT_EQ(comparable(tmp.path + "/r3"), r1);

  // A third run does nothing new.
  auto d = pbcli::run("run exp.yaml --out r3 --jobs 2 " + common(), tmp.path);
  ASSERT_EQ(d.code, 0) << d.err;
  EXPECT_NE(d.out.find("0 run now"), std::string::npos) << d.out;

  // The reporter reads it back into a thesis-layout table.
  auto rep = pbcli::run("report r1 --format md,csv", tmp.path);
  ASSERT_EQ(rep.code, 0) << rep.err;
  EXPECT_NE(rep.out.find("| table_small | robustness |"), std::string::npos) << rep.out;
  EXPECT_TRUE(fs::exists(tmp.path + "/r1/report.csv"));

  // Another experiment into the same folder: exit 2, records untouched.
  const std::string before = pbcli::slurp(tmp.path + "/r1/records.jsonl");
  pbcli::write_file(tmp.path + "/other.yaml", experiment_yaml(tmp.path + "/scene.yaml") + "timeout_s: 99\n");
  auto e = pbcli::run("run other.yaml --out r1 " + common(), tmp.path);
  EXPECT_EQ(e.code, 2);
  EXPECT_NE(e.err.find("experiment.json"), std::string::npos) << e.err;
  EXPECT_NE(e.err.find("another experiment"), std::string::npos) << e.err;
  EXPECT_EQ(pbcli::slurp(tmp.path + "/r1/records.jsonl"), before);
}

// The sensor's floor of relative lengths comes from the scene's first image
// and the trial's scale settings: a worker that runs every trial (one job)
// computes it once per scene and scale setting, and two settings of
// scale.sensor_floor_px in one sweep still get their own floors (here the
// pixel footprint term: 2 and 200 footprints at the median depth).
TEST_F(RunTest, SensorFloorFollowsTheScaleSettingsOfEachGridPoint) {
  pbcli::write_file(tmp.path + "/floor.yaml",
                    "name: floortest\nseed: 3\nobject: ls5\nscenes:\n  - name: table_small\n    generate: " +
                        tmp.path + "/scene.yaml\n    scenario: table\ndescriptors: [cvfh]\nrefinements: [icp]\n" +
                        "settings:\n  views: {views: 4}\ngrid:\n  scale.sensor_floor_px: [2, 200]\n");
  auto r = pbcli::run("run floor.yaml --out rf --jobs 1 " + common(), tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  std::map<double, std::vector<double>> floors;  // sensor_floor_px -> min_length_mm of each image
  for (const auto& [key, rec] : comparable(tmp.path + "/rf")) {
    ASSERT_NE(rec["status"], "error") << key;  // at 200 footprints nothing is found: no matter
    floors[rec["settings_resolved"]["scale"]["sensor_floor_px"].get<double>()].push_back(
        rec["settings_resolved"]["scale"]["min_length_mm"].get<double>());
  }
  ASSERT_EQ(floors.size(), 2u);
  for (const auto& [px, v] : floors) {
    ASSERT_EQ(v.size(), 3u) << px;
    for (double m : v) EXPECT_EQ(m, v[0]) << "every image of the scene shares its first image's floor";
  }
  // 200 footprints against 2: at most 100 times the floor (the noise term may
  // dominate at 2), and far above it.
  const double ratio = floors[200][0] / floors[2][0];
  EXPECT_GT(ratio, 40.0);
  EXPECT_LE(ratio, 100.0 * (1 + 1e-12));
}

TEST_F(RunTest, UnknownKeyIsExit2NamingFileLineAndKey) {
  pbcli::write_file(tmp.path + "/bad.yaml", experiment_yaml(tmp.path + "/scene.yaml") + "descriptorz: [esf]\n");
  auto r = pbcli::run("run bad.yaml --out rb " + common(), tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("descriptorz"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("line 13"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/rb/records.jsonl"));
}

TEST_F(RunTest, UnknownSettingInsideASectionIsExit2) {
  pbcli::write_file(tmp.path + "/bad.yaml",
                    experiment_yaml(tmp.path + "/scene.yaml") + "grid:\n  local.hough_binn_mm: [10, 20]\n");
  auto r = pbcli::run("run bad.yaml --out rb " + common(), tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("hough_binn_mm"), std::string::npos) << r.err;
}

TEST_F(RunTest, MalformedYamlIsExit2) {
  pbcli::write_file(tmp.path + "/bad.yaml", "name: x\nscenes: [\n");
  auto r = pbcli::run("run bad.yaml --out rb " + common(), tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("malformed YAML"), std::string::npos) << r.err;
}

TEST_F(RunTest, DatasetThatIsNotBopIsExit2) {
  fs::create_directories(tmp.path + "/notbop/stuff");
  pbcli::write_file(tmp.path + "/bad.yaml",
                    "object: ls5\nscenes:\n  - dataset: " + tmp.path + "/notbop\ndescriptors: [fpfh]\n");
  auto r = pbcli::run("run bad.yaml --out rb " + common(), tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("notbop"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/rb")) << "a failed run must not leave a results folder";
}

// views.follow_scene reads the scene set's camera elevations: a generated
// set runs; the same set without its posebench_scene.json is exit 2 naming
// that file and the setting, before any trial runs.
TEST_F(RunTest, FollowSceneViewsNeedAGeneratedSceneSet) {
  auto g = pbcli::run("generate scene.yaml --out ds --images 1 --quiet", tmp.path);
  ASSERT_EQ(g.code, 0) << g.err;
  const std::string exp = "object: ls5\nscenes:\n  - dataset: " + tmp.path + "/ds\n    scenario: table\n"
                          "descriptors: [cvfh]\nrefinements: [icp]\nsettings:\n  views: {views: 1, follow_scene: true}\n";
  pbcli::write_file(tmp.path + "/follow.yaml", exp);
  auto ok = pbcli::run("run follow.yaml --out rf " + common(), tmp.path);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(pbcli::records_by_key(tmp.path + "/rf/records.jsonl").size(), 1u);

  fs::remove(tmp.path + "/ds/posebench_scene.json");
  auto r = pbcli::run("run follow.yaml --out rb " + common(), tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("ds/posebench_scene.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("views.follow_scene"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp.path + "/rb/records.jsonl"));
}

TEST_F(RunTest, ReportOnAFolderWithoutRecordsIsExit2) {
  fs::create_directories(tmp.path + "/empty");
  auto r = pbcli::run("report empty", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("experiment.json"), std::string::npos) << r.err;
}

}  // namespace
