// CI regression on robustness: runs configs/experiments/ci.yaml (every
// descriptor on 10 fixed table images) and compares each method's robustness
// with the committed expected values (configs/experiments/ci_expected.yaml),
// failing when one drops below its expected value by more than the tolerance.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <nlohmann/json.hpp>

#include "cli_test_util.h"

namespace {

TEST(Regression, RobustnessPerMethodDoesNotDropBelowExpected) {
  const std::string src = POSEBENCH_SOURCE_DIR;
  const YAML::Node expected = YAML::LoadFile(src + "/configs/experiments/ci_expected.yaml");
  const double tolerance = expected["tolerance"].as<double>();
  pbcli::TempDir tmp;
  // Run from the source tree (the config's paths are relative to it); the
  // output, scenes and cache go to the temporary folder.
  const auto r = pbcli::run("run configs/experiments/ci.yaml --jobs 2 -q --out '" + tmp.path + "/r' --scenes '" +
                                tmp.path + "/scenes' --cache '" + tmp.path + "/cache'",
                            src);
  ASSERT_EQ(r.code, 0) << r.err;

  std::map<std::string, std::pair<int, int>> counts;  // descriptor -> (correct, trials)
  std::ifstream in(tmp.path + "/r/records.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    auto& c = counts[j["descriptor"].get<std::string>()];
    c.second += 1;
    c.first += j.value("correct", false) ? 1 : 0;
    EXPECT_NE(j.value("status", ""), "error") << j.value("message", "");
  }
  for (const auto& kv : expected["robustness"]) {
    const std::string method = kv.first.as<std::string>();
    const double want = kv.second.as<double>();
    ASSERT_TRUE(counts.count(method)) << "no trials of " << method;
    const auto [correct, trials] = counts[method];
    ASSERT_EQ(trials, 10) << method;
    const double got = static_cast<double>(correct) / trials;
    EXPECT_GE(got, want - tolerance) << method << ": robustness " << got << " < expected " << want
                                     << " - tolerance " << tolerance;
    std::printf("%-8s robustness %.2f (expected %.2f)\n", method.c_str(), got, want);
  }
}

}  // namespace
