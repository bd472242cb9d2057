// The bench-pipeline table: stage medians, the p90 total, robustness with
// its Wilson interval and the budget verdict, from hand-made records.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/stats.h"
#include "report/bench.h"

namespace {

pb::TrialRecord rec(const std::string& scene, const std::string& scenario, const std::string& desc, bool correct,
                    double pre, double describe, double refine, double verify) {
  pb::TrialRecord r;
  r.scene = scene;
  r.scenario = scenario;
  r.descriptor = desc;
  r.refinement = "icp";
  r.status = correct ? "ok" : "no_hypothesis";
  r.correct = correct;
  pb::StageTimes t;
  t.preprocess = pre;
  t.describe = describe;
  t.refine = refine;
  t.verify = verify;
  r.times = pb::StageTimesRecord::from(t);
  r.hypotheses = 4;
  return r;
}

TEST(Stats, WilsonIntervalAndQuantilesMatchHandValues) {
  const pb::Proportion p = pb::wilson(8, 10);
  EXPECT_NEAR(p.lo, 0.4902, 1e-4);  // standard Wilson 95% values for 8 of 10
  EXPECT_NEAR(p.hi, 0.9433, 1e-4);
  EXPECT_EQ(pb::wilson(0, 0).hi, 1.0);
  EXPECT_NEAR(pb::wilson(0, 5).hi, 0.4345, 1e-4);
  EXPECT_DOUBLE_EQ(pb::median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(pb::median({4, 1, 2, 3}), 2.5);
  EXPECT_DOUBLE_EQ(pb::quantile({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, 0.9), 9.1);
  EXPECT_TRUE(std::isnan(pb::median({})));
}

TEST(BenchTable, RowsHoldStageMediansRobustnessAndTheBudgetVerdict) {
  const std::vector<pb::TrialRecord> records = {
      rec("table_astra", "table", "cvfh", true, 0.010, 0.005, 0.010, 0.001),   // total 0.026
      rec("table_astra", "table", "cvfh", true, 0.012, 0.006, 0.020, 0.002),   // total 0.040
      rec("table_astra", "table", "cvfh", false, 0.011, 0.004, 0.005, 0.001),  // total 0.021
      rec("warehouse", "warehouse", "cvfh", true, 0.05, 0.1, 1.0, 0.05),
  };
  const pb::BenchTable t = pb::bench_table(records, {{"table", 0.033}, {"warehouse", 0.1}});
  ASSERT_EQ(t.rows.size(), 2u);
  const pb::BenchRow& a = t.rows[0];
  EXPECT_EQ(a.scene, "table_astra");
  EXPECT_EQ(a.trials, 3);
  EXPECT_EQ(a.correct.k, 2);
  EXPECT_EQ(a.correct.n, 3);
  EXPECT_DOUBLE_EQ(a.preprocess_s, 0.011);
  EXPECT_DOUBLE_EQ(a.hypothesize_s, 0.005);
  EXPECT_DOUBLE_EQ(a.refine_s, 0.010);
  EXPECT_NEAR(a.total_s, 0.026, 1e-12);
  EXPECT_NEAR(a.total_p90_s, 0.026 + 0.8 * (0.040 - 0.026), 1e-12);
  EXPECT_TRUE(a.within_budget());
  EXPECT_FALSE(t.rows[1].within_budget());
  const std::string md = pb::bench_markdown(t);
  EXPECT_NE(md.find("| table_astra | cvfh+icp | 11.0 | 5.00 | 10.0 | 1.00 | 26.0 | 37.2 | 33.0 met | 4 | 2/3 ["),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("100.0 missed"), std::string::npos) << md;
  const auto j = pb::bench_json(t);
  EXPECT_EQ(j.at("rows").at(0).at("correct").at("k"), 2);
  EXPECT_NEAR(j.at("rows").at(1).at("median_s").at("total").get<double>(), 1.2, 1e-12);
  // No settings given: no settings list.
  EXPECT_EQ(md.find("Settings over the defaults"), std::string::npos) << md;
  EXPECT_TRUE(j.at("settings").empty());

  // The settings the config gives, listed under the table and in the JSON.
  pb::BenchTable with = t;
  with.settings["all"] = {{"refine", {{"max_hypotheses", 5}}}};
  with.settings["table_astra"] = {{"local", {{"keypoint_voxel_mm", 15}}}};
  const std::string md2 = pb::bench_markdown(with);
  EXPECT_NE(md2.find("- every scene set: `{\"refine\":{\"max_hypotheses\":5}}`"), std::string::npos) << md2;
  EXPECT_NE(md2.find("- table_astra: `{\"local\":{\"keypoint_voxel_mm\":15}}`"), std::string::npos) << md2;
  EXPECT_EQ(pb::bench_json(with).at("settings").at("table_astra").at("local").at("keypoint_voxel_mm"), 15);
}

}  // namespace
