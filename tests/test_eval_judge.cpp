// The one judge (eval/judge.h): an estimate is judged against the ground-truth
// instance it fits best, not the first listed; in rank order a correct
// estimate takes its instance, so a second estimate of the same instance is
// not correct; an image without instances judges nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "eval/judge.h"

namespace {

pb::Pose at(double x, double yaw_deg = 0) {
  pb::Pose T;
  T.R = Eigen::AngleAxisd(yaw_deg * M_PI / 180, pb::Vec3::UnitZ()).toRotationMatrix();
  T.t = pb::Vec3(x, 0, 1000);
  return T;
}

const pb::ThesisThresholds kTable{50.0, 0.05};

TEST(Judge, TheInstanceTheEstimateFitsNotTheFirstListed) {
  const std::vector<pb::Pose> gts = {at(0), at(300)};
  const pb::InstanceJudgement j = pb::judge(at(310, 5), gts, {}, kTable);
  EXPECT_EQ(j.gt, 1);
  EXPECT_TRUE(j.judged.correct);
  EXPECT_NEAR(j.judged.errors.translation_mm, 10.0, 1e-9);
  // Wrong everywhere: still judged against the nearer instance, not correct.
  const pb::InstanceJudgement far = pb::judge(at(220), gts, {}, kTable);
  EXPECT_EQ(far.gt, 1);
  EXPECT_FALSE(far.judged.correct);
  EXPECT_NEAR(far.judged.errors.translation_mm, 80.0, 1e-9);
}

TEST(Judge, ACorrectFitBeatsANearerTranslationWithAWrongRotation) {
  // 20 mm from instance 0 but turned 90 degrees from it; 40 mm from instance 1 at its rotation.
  const std::vector<pb::Pose> gts = {at(0, 90), at(60)};
  const pb::InstanceJudgement j = pb::judge(at(20), gts, {}, kTable);
  EXPECT_EQ(j.gt, 1);
  EXPECT_TRUE(j.judged.correct);
}

TEST(Judge, InRankOrderAnInstanceIsTakenOnce) {
  const std::vector<pb::Pose> gts = {at(0), at(300)};
  const auto j = pb::judge_in_order({at(5), at(8), at(295)}, gts, {}, kTable);
  ASSERT_EQ(j.size(), 3u);
  EXPECT_EQ(j[0].gt, 0);
  EXPECT_TRUE(j[0].judged.correct);
  EXPECT_EQ(j[1].gt, 1);  // instance 0 is taken: the other is 292 mm away
  EXPECT_FALSE(j[1].judged.correct);
  EXPECT_EQ(j[2].gt, 1);  // the wrong second estimate did not take it
  EXPECT_TRUE(j[2].judged.correct);
}

TEST(Judge, NoInstancesOrANonFinitePose) {
  EXPECT_EQ(pb::judge(at(0), {}, {}, kTable).gt, -1);
  pb::Pose bad = at(0);
  bad.t.x() = std::numeric_limits<double>::quiet_NaN();
  const pb::InstanceJudgement j = pb::judge(bad, {at(0), at(300)}, {}, kTable);
  EXPECT_EQ(j.gt, 0);  // the first, as every fit is unknown
  EXPECT_FALSE(j.judged.correct);
}

}  // namespace
