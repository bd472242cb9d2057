// The report's resolved lengths (issue 9): per scene set and object, every
// length a trial resolved (settings_resolved, mm), a range where the
// group's records differ; sentinels (negative) and non-lengths left out.
#include <gtest/gtest.h>

#include "report/lengths.h"

namespace {

pb::TrialRecord record(const std::string& scene, int obj, double voxel, double floor_mm) {
  pb::TrialRecord r;
  r.scene = scene;
  r.obj_id = obj;
  r.settings_resolved = nlohmann::json{{"preprocess", {{"voxel_mm", voxel}, {"plane_iterations", 200}}},
                                       {"refine", {{"crop_margin_mm", -1.0}, {"max_correspondence_mm", 2 * voxel}}},
                                       {"scale", {{"min_length_mm", floor_mm}, {"length_factor", 1.0}}}};
  return r;
}

TEST(ReportLengths, PerSceneAndObjectWithRanges) {
  std::vector<pb::TrialRecord> recs{record("lmo", 1, 5, 3.9), record("lmo", 1, 6, 3.9), record("lmo", 5, 10.1, 3.9)};
  recs.emplace_back();  // a failed worker: no settings_resolved
  recs.back().scene = "lmo";
  const auto groups = pb::resolved_lengths(recs);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].group, "lmo, obj 1");
  EXPECT_EQ(groups[0].range_mm.at("preprocess.voxel_mm"), std::make_pair(5.0, 6.0));
  EXPECT_EQ(groups[0].range_mm.at("refine.max_correspondence_mm"), std::make_pair(10.0, 12.0));
  EXPECT_EQ(groups[1].range_mm.at("scale.min_length_mm"), std::make_pair(3.9, 3.9));
  EXPECT_EQ(groups[0].range_mm.count("refine.crop_margin_mm"), 0u);      // the -1 sentinel
  EXPECT_EQ(groups[0].range_mm.count("preprocess.plane_iterations"), 0u);  // not a length
  const std::string md = pb::resolved_lengths_markdown(groups);
  EXPECT_NE(md.find("| setting | lmo, obj 1 | lmo, obj 5 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| preprocess.voxel_mm | 5-6 | 10.1 |"), std::string::npos) << md;
  EXPECT_EQ(pb::resolved_lengths_markdown({}), "");
}

}  // namespace
