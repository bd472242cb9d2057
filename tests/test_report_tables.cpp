// The reporter's tables: cells computed from records match hand-computed
// robustness, accuracy and time, and the thesis's values sit beside them.
#include <gtest/gtest.h>

#include <cmath>

#include "report/report.h"

namespace {

pb::TrialRecord rec(const std::string& scene, const std::string& desc, bool ok, double t_err, double r_err,
                   double time) {
  pb::TrialRecord r;
  r.scene = scene;
  r.descriptor = desc;
  r.refinement = "icp";
  r.status = ok ? "ok" : "no_hypothesis";
  r.times = pb::StageTimesRecord{};
  r.times->total = time;
  if (ok) r.errors = pb::ThesisErrorsRecord{t_err, r_err, 1.0, 0, t_err, r_err};
  return r;
}

nlohmann::json experiment() {
  return {{"name", "t"},
          {"descriptors", {"cvfh", "fpfh"}},
          {"refinements", {"icp"}},
          {"added_noise_mm", {0.0}},
          {"thresholds", {50.0, 100.0, 0.05}},
          {"scenes", {{{"name", "table_synthetic"}, {"scenario", "table"}}}},
          {"report", {{"reference_table", "4.1"}}}};
}

TEST(Report, CellsMatchHandComputedAggregates) {
  std::vector<pb::TrialRecord> records = {
      rec("table_synthetic", "cvfh", true, 10.0, 0.01, 0.2),   // correct
      rec("table_synthetic", "cvfh", true, 30.0, 0.03, 0.4),   // correct
      rec("table_synthetic", "cvfh", true, 60.0, 0.01, 0.3),   // translation too large
      rec("table_synthetic", "cvfh", false, 0, 0, 0.5),        // no hypothesis
      rec("table_synthetic", "fpfh", true, 5.0, 0.001, 1.0),   // correct
  };
  pb::ReportOptions opt;
  opt.reference_file = std::string(POSEBENCH_SOURCE_DIR) + "/configs/thesis/reference.yaml";
  const pb::Report r = pb::build_report(experiment(), records, opt);
  ASSERT_EQ(r.tables.size(), 1u);
  const auto& t = r.tables[0];
  ASSERT_EQ(t.columns, (std::vector<std::string>{"cvfh", "fpfh"}));
  ASSERT_EQ(t.rows.size(), 8u);  // 4 thesis measures + BOP AR and its 3 components
  EXPECT_EQ(t.rows[0].measure, "robustness");
  EXPECT_DOUBLE_EQ(t.rows[0].cells[0].value, 0.5);
  EXPECT_DOUBLE_EQ(t.rows[0].cells[1].value, 1.0);
  EXPECT_DOUBLE_EQ(t.rows[0].cells[0].reference, 0.43);  // Table 4.1, table synthetic, CVFH
  EXPECT_DOUBLE_EQ(t.rows[0].cells[1].reference, 0.67);
  EXPECT_EQ(t.rows[1].measure, "translation_mm");
  EXPECT_DOUBLE_EQ(t.rows[1].cells[0].value, 20.0);
  EXPECT_NEAR(t.rows[2].cells[0].value, 0.02, 1e-12);
  EXPECT_EQ(t.rows[3].measure, "time");
  EXPECT_NEAR(t.rows[3].cells[0].value, (0.2 + 0.4 + 0.3 + 0.5) / 4, 1e-12);
  EXPECT_EQ(t.rows[4].measure, "bop_ar");
  EXPECT_DOUBLE_EQ(t.rows[4].cells[0].value, 0.0);  // no BOP errors recorded: nothing recalled
  const std::string md = pb::to_markdown(r);
  EXPECT_NE(md.find("50% (43%)"), std::string::npos) << md;
  EXPECT_NE(md.find("100% (67%)"), std::string::npos) << md;
  const std::string csv = pb::to_csv(r);
  EXPECT_NE(csv.find("table_synthetic,robustness,cvfh,0.5,0.43,4"), std::string::npos) << csv;
}

// An experiment's extra judgement (the carton's faces on faces) gets its own
// robustness row after the main one, from the records' judgements.NAME.
TEST(Report, ExtraJudgementRowFromTheRecordsJudgements) {
  std::vector<pb::TrialRecord> records = {
      rec("table_synthetic", "cvfh", true, 10.0, 0.01, 0.2),  // correct both ways
      rec("table_synthetic", "cvfh", true, 10.0, 0.4, 0.2),   // turned: correct on faces only
      rec("table_synthetic", "cvfh", true, 70.0, 0.4, 0.2),   // wrong both ways
      rec("table_synthetic", "cvfh", false, 0, 0, 0.5),       // no pose: not judged, not correct
  };
  records[0].judgements["faces"] = pb::JudgementRecord{true, 10.0, 0.01};
  records[1].judgements["faces"] = pb::JudgementRecord{true, 10.0, 0.0};
  records[2].judgements["faces"] = pb::JudgementRecord{false, 70.0, 0.0};
  const pb::Report r = pb::build_report(experiment(), records, {});
  ASSERT_EQ(r.tables.size(), 1u);
  const auto& t = r.tables[0];
  ASSERT_EQ(t.rows.size(), 9u);
  EXPECT_EQ(t.rows[0].measure, "robustness");
  EXPECT_DOUBLE_EQ(t.rows[0].cells[0].value, 0.25);
  EXPECT_EQ(t.rows[1].measure, "robustness_faces");
  EXPECT_DOUBLE_EQ(t.rows[1].cells[0].value, 0.5);
  EXPECT_EQ(t.rows[1].cells[0].trials, 4);
  EXPECT_FALSE(t.rows[1].detail);
  EXPECT_EQ(t.rows[2].measure, "translation_mm");
  const std::string md = pb::to_markdown(r);
  EXPECT_NE(md.find("| robustness, judged by faces | 50% |"), std::string::npos) << md;
}

TEST(Report, BopAverageRecallFromRecordedErrors) {
  // One image, diameter 100 mm, MSSD 12 mm: correct for MSSD thresholds
  // 0.15..0.5 of the diameter (8 of 10); MSPD 7 px at width 640: correct for
  // 10..50 px (9 of 10); VSD 0.07 for every tau: correct for thresholds
  // 0.10..0.50 (9 of 10).
  auto r = rec("table_synthetic", "cvfh", true, 10.0, 0.01, 0.2);
  r.bop = pb::BopErrorsRecord{12.0, 7.0, std::vector<double>(10, 0.07), 100.0, 640};
  const pb::Report rep = pb::build_report(experiment(), std::vector<pb::TrialRecord>{r}, {});
  const auto& rows = rep.tables.at(0).rows;
  auto value = [&](const std::string& m) {
    for (const auto& row : rows)
      if (row.measure == m) return row.cells[0].value;
    return -1.0;
  };
  EXPECT_NEAR(value("bop_ar_mssd"), 0.8, 1e-12);
  EXPECT_NEAR(value("bop_ar_mspd"), 0.9, 1e-12);
  EXPECT_NEAR(value("bop_ar_vsd"), 0.9, 1e-12);
  EXPECT_NEAR(value("bop_ar"), (0.8 + 0.9 + 0.9) / 3, 1e-12);
}

TEST(Report, NoiseSweepMakesOnePlotSeriesPerMethod) {
  auto exp = experiment();
  exp["added_noise_mm"] = {0.0, 5.0};
  std::vector<pb::TrialRecord> records;
  for (double n : {0.0, 5.0})
    for (int i = 0; i < 2; ++i) {
      auto r = rec("table_synthetic", "cvfh", n == 0.0 || i == 0, 10, 0.01, 0.1);
      r.added_noise_mm = n;
      records.push_back(r);
    }
  const pb::Report r = pb::build_report(exp, records, {});
  ASSERT_EQ(r.plots.size(), 1u);
  ASSERT_EQ(r.plots[0].series.size(), 1u);
  EXPECT_EQ(r.plots[0].series[0].x, (std::vector<double>{0.0, 5.0}));
  EXPECT_EQ(r.plots[0].series[0].robustness, (std::vector<double>{1.0, 0.5}));
  EXPECT_EQ(r.tables.size(), 2u);  // one table per noise level
}

}  // namespace
