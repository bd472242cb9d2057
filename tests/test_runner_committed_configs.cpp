// Every experiment config the project commits loads: configs/experiments,
// configs/thesis (with the probes of configs/thesis/findings) and configs/bench
// (a YAML with `scenes` and `descriptors` at the top), and so does every
// ablation experiment scripts/thesis_ablations.py derives from
// configs/thesis/ablations.yaml. Loading validates
// every key of every settings section, so a misspelt or removed setting in
// a committed config fails here, not in a user's run. And a config with a
// misspelt setting is the InputError a user would get: the file, the key
// path and the allowed keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/yaml.h"
#include "runner/experiment.h"

namespace {

namespace fs = std::filesystem;

// The YAML files under `dir` (recursively) that are experiments.
std::vector<std::string> experiments_under(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file() || e.path().extension() != ".yaml") continue;
    const pb::YamlNode root = pb::YamlNode::load_file(e.path().string());
    if (root.is_map() && root.has("scenes") && root.has("descriptors")) out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(CommittedConfigs, EveryExperimentLoads) {
  fs::current_path(POSEBENCH_SOURCE_DIR);  // the configs' paths are relative to the project root
  // The real-data configs name their dataset as ${POSEBENCH_REAL_DATA}/...;
  // loading checks the settings, not that the data is there, so without the
  // data a stand-in root lets them load all the same.
  setenv("POSEBENCH_REAL_DATA", "/nonexistent/real_data", /*overwrite=*/0);
  size_t loaded = 0;
  for (const char* dir : {"configs/experiments", "configs/thesis", "configs/bench"}) {
    const std::vector<std::string> files = experiments_under(dir);
    EXPECT_FALSE(files.empty()) << dir;
    for (const std::string& f : files) {
      SCOPED_TRACE(f);
      try {
        const pb::ExperimentConfig cfg = pb::load_experiment(f);
        EXPECT_FALSE(cfg.scenes.empty());
        EXPECT_FALSE(cfg.descriptors.empty());
        ++loaded;
      } catch (const std::exception& e) {
        ADD_FAILURE() << e.what();
      }
    }
  }
  EXPECT_GE(loaded, 20u);
}

TEST(CommittedConfigs, EveryDerivedAblationLoads) {
  fs::current_path(POSEBENCH_SOURCE_DIR);
  const std::string out = ::testing::TempDir() + "/ablations";
  fs::remove_all(out);
  const std::string cmd = "python3 scripts/thesis_ablations.py configs/thesis/ablations.yaml " + out + " > /dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const std::vector<std::string> files = experiments_under(out);
  EXPECT_GE(files.size(), 20u);
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    try {
      EXPECT_FALSE(pb::load_experiment(f).descriptors.empty());
    } catch (const std::exception& e) {
      ADD_FAILURE() << e.what();
    }
  }
}

TEST(CommittedConfigs, TheBenchConfigWithAMisspeltSettingNamesFileKeyAndAllowedKeys) {
  fs::current_path(POSEBENCH_SOURCE_DIR);
  std::ifstream in("configs/bench/pipeline.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string good = "esf_samples_from_points: true}";
  const size_t at = text.find(good);
  ASSERT_NE(at, std::string::npos) << "the bench config sets global.esf_samples_from_points";
  text.replace(at, good.size(), "esf_samples_from_point: true}");
  const std::string path = ::testing::TempDir() + "/bench_typo.yaml";
  std::ofstream(path) << text;
  try {
    pb::load_experiment(path);
    FAIL() << "a misspelt setting loaded";
  } catch (const pb::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("scenes[0].settings.global.esf_samples_from_point'"), std::string::npos) << what;
    EXPECT_NE(what.find("unknown key"), std::string::npos) << what;
    EXPECT_NE(what.find("esf_samples_from_points"), std::string::npos) << what;  // among the allowed keys
  }
}

}  // namespace
