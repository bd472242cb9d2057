// posebench bench-pipeline on a small timing experiment: exit 0, the table
// in bench.md and bench.json with one row per scene x method, and the run's
// records behind it; a bad config is exit 2 naming the file.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.h"
#include "test_cli_run_scene.h"

namespace {

TEST(CliBenchPipeline, WritesOneRowPerSceneAndMethodFromTheRunsRecords) {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/scene.yaml", pbcli::kSmallTableScene);
  pbcli::write_file(tmp.path + "/bench.yaml", "name: b\nseed: 1\nobject: ls5\nscenes:\n  - name: small\n"
                                              "    generate: " + tmp.path + "/scene.yaml\n    scenario: table\n"
                                              "    settings: {global: {esf_samples_from_points: true}}\n"
                                              "descriptors: [cvfh, ppf]\nrefinements: [icp]\n");
  const auto r = pbcli::run("bench-pipeline bench.yaml --out out --cache '' --scenes s -q", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(pbcli::slurp(tmp.path + "/out/bench.json"));
  ASSERT_EQ(j.at("rows").size(), 2u) << j.dump(1);
  for (const auto& row : j.at("rows")) {
    EXPECT_EQ(row.at("scene"), "small");
    EXPECT_EQ(row.at("trials"), 3);
    EXPECT_GT(row.at("median_s").at("total").get<double>(), 0.0);
    EXPECT_EQ(row.at("budget_s"), 0.033);
  }
  EXPECT_EQ(j.at("host").at("omp_threads"), 1);
  const std::string md = pbcli::slurp(tmp.path + "/out/bench.md");
  EXPECT_NE(md.find("| small | cvfh+icp |"), std::string::npos) << md;
  EXPECT_NE(md.find("| small | ppf+icp |"), std::string::npos) << md;
  EXPECT_NE(r.out.find("| small | ppf+icp |"), std::string::npos);
  // What was timed: the scene set's own settings, in both files.
  EXPECT_EQ(j.at("settings").at("small").at("global").at("esf_samples_from_points"), true) << j.dump(1);
  EXPECT_FALSE(j.at("settings").contains("all")) << j.dump(1);
  EXPECT_NE(md.find("- small: `{\"global\":{\"esf_samples_from_points\":true}}`"), std::string::npos) << md;
}

TEST(CliBenchPipeline, BadConfigIsExit2NamingTheFile) {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/bad.yaml", "name: b\nseed: [\n");
  const auto r = pbcli::run("bench-pipeline bad.yaml --out out -q", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
}

}  // namespace
