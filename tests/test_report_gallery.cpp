// The gallery's choice of trials (report/gallery.h select_gallery) and the
// base64 the HTML page embeds images with (report/html.h).
#include <gtest/gtest.h>

#include "report/gallery.h"
#include "report/html.h"

using namespace pb;

namespace {

TrialRecord rec(const std::string& key, const std::string& desc, bool correct, double t_mm, bool pose = true) {
  TrialRecord r;
  r.key = key;
  r.descriptor = desc;
  r.refinement = "icp";
  r.status = pose ? "ok" : "no_hypothesis";
  r.correct = correct;
  if (pose) {
    r.estimate = PoseRecord::from(Pose{});
    r.errors = ThesisErrorsRecord{t_mm, 0, 0, 0, t_mm, 0};
  }
  return r;
}

std::vector<std::string> keys(const std::vector<GalleryItem>& items) {
  std::vector<std::string> k;
  for (const auto& i : items) k.push_back(i.record->key + (i.success ? "+" : "-"));
  return k;
}

}  // namespace

TEST(ReportGallery, WorstFailuresThenClosestSuccessesPerMethod) {
  const std::vector<TrialRecord> recs = {
      rec("a", "fpfh", false, 40), rec("b", "fpfh", true, 3),  rec("c", "fpfh", false, 400),
      rec("d", "fpfh", false, 0, false), rec("e", "fpfh", true, 9), rec("f", "fpfh", true, 1),
      rec("g", "fpfh", false, 90), rec("h", "shot", true, 2),
  };
  const auto g = select_gallery(recs);
  ASSERT_EQ(g.size(), 2u);
  // Failures with a pose by decreasing error, then those without; successes
  // by decreasing error.
  EXPECT_EQ(keys(g.at("fpfh+icp")), (std::vector<std::string>{"c-", "g-", "a-", "e+", "b+"}));
  EXPECT_EQ(keys(g.at("shot+icp")), (std::vector<std::string>{"h+"}));
  GalleryOptions more;
  more.failures = 10;
  EXPECT_EQ(keys(select_gallery(recs, more).at("fpfh+icp")),
            (std::vector<std::string>{"c-", "g-", "a-", "d-", "e+", "b+"}));
}

TEST(ReportGallery, Base64IsRfc4648) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\x80", 3)), "/wCA");
}
