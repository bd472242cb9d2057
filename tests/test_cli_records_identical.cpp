// Refactors change no result: every record of configs/experiments/ci.yaml
// and demo.yaml has the same status, estimated pose, errors (thesis and BOP),
// correctness, score, inliers, hypothesis count and ground truth, bit for
// bit (exact JSON numbers), as tests/data/expected_records/*.jsonl. Those
// were written from a run of commit 4906144 with the same commands (before
// the structure refactor, issue 7, which changed nothing), then rewritten
// when the project's own ICP replaced PCL's (issue 8: same correctness in
// every record, translations within 0.27 mm of PCL's, float rounding), and
// again when the own normals and the subset-scored RANSAC plane replaced
// PCL's normals and the all-points scoring (ci: the same correctness in
// every record but one SHOT image, now correct: 6 of 10, was 5), and when
// PPF began pairing the scene at the model's sampling (ci: PPF's estimates
// moved by at most 1.7 mm, the same 8 of 10 correct), and when the
// project's own FPFH replaced PCL's (float rounding in the descriptors: ci
// 4 FPFH estimates changed, demo 1 by 0.13 mm; the same correctness in every
// record, FPFH 8 of 10 in ci, 3 in demo), and when the project's own SHOT
// replaced PCL's (float rounding in the descriptors: ci 4 SHOT estimates
// changed, the two correct ones by at most 0.21 mm, demo 2; the same
// correctness in every record, SHOT 6 of 10 in ci, 2 in demo), and when the
// project's own BOARD frames replaced PCL's (plane normal from the covariance,
// a deterministic hole-search start axis instead of std::rand(): ci 3 FPFH
// and 3 SHOT estimates moved, the correct ones by at most 0.63 mm (demo: 0.74), demo 1
// FPFH and 2 SHOT; the same correctness in every record), and when the
// default lengths became relative to the object's diameter (issue 9: the
// configs pin voxel, keypoint voxel and Hough bin in mm, Table 4.2; every
// other length is now a fraction of the LS5's 179.6 mm diameter instead of
// the mm value meant for 200 mm, about 10% shorter; every estimate moved;
// ci correct per method before -> after: cesf 2 -> 7, cvfh 4 -> 3, esf 6 ->
// 6, fpfh 8 -> 7, ourcvfh 4 -> 5, ppf 8 -> 7, shot 6 -> 7 of 10; demo: cesf
// 1 -> 3, cvfh 1 -> 1, fpfh 3 -> 2, shot 2 -> 3 of 4), and when
// verification by the depth image became the default (verify.score:
// visibility instead of inliers; ci: cesf 7, cvfh 3, esf 6 unchanged, fpfh
// 7 -> 9, ourcvfh 5 -> 4, ppf 7 -> 10, shot 7 -> 9 of 10, 40 estimates
// moved; demo: fpfh 2 -> 3 of 4, 6 estimates moved), and when PPF's
// defaults took Vidal et al.'s sampling (model at 2 distance steps with
// normal clustering, one vote per quantized scene pair; ci: ppf 10 -> 8 of
// 10, all 10 estimates moved: image 0 ranks a 90-degree turn above the
// correct hypothesis, image 3 has no correct hypothesis; on the 30 occluded
// images of configs/experiments/ppf.yaml it is 13 -> 15), and when the BOARD
// frames began summing their neighbours in kd-tree order instead of distance
// order (float rounding in the frames, so Hough votes move: ci 3 FPFH and 1
// SHOT estimates moved, the two correct ones by 0.77 and 0.20 mm; demo 2 FPFH
// and 1 SHOT; the same correctness in every record), and when CESF began
// describing a cluster without a stable region by the ESF of the whole
// cluster, as CVFH does (ci: one CESF record, image 4, changed: 11 -> 15
// hypotheses, wrong before and after; demo unchanged), and when FPFH matching
// moved from FLANN's kd-tree to the bounded scan, which breaks exact ties
// (equal distances to rows 424 or 848 apart, seen on two of Table 4.1's
// Astra images: identical descriptors in several training views) toward the
// lower row where the tree took whichever it met first (ci: 9 FPFH estimates
// moved, image 0 turned wrong, FPFH 9 -> 8 of 10; demo: the same image, 3 ->
// 2 of 4; a tie-break flip, not a weakening: on Table 4.1's 220 FPFH trials
// the scan is 202 correct against the tree's 201, the scan with ties toward
// the higher row 199), and when CVFH's stable regions moved from PCL
// (pcl::NormalEstimation and CVFH's region growing on an unsorted FLANN
// tree, which skips the first neighbour each search returns, not always the
// seed) to the project's kd-tree and normals (the regions of PCL's
// algorithm on a sorted search: 1-2 more points in some regions) and CVFH
// to its own VFH (ci: every CVFH and CESF estimate moved; CVFH 3 -> 3 of
// 10, CESF 7 -> 4, a re-draw of ESF's random triples over the changed
// regions; demo: CESF 3 -> 2 of 4; see results/bench/README.md, the
// twenty-fifth round, for the thesis experiments), and when OUR-CVFH took
// those regions and that VFH too, keeping PCL's frames and shape
// distribution (ci: every OUR-CVFH estimate moved, 4 -> 4 of 10), and when
// the stable regions' normals came from a coarse support where the cloud is
// dense (global.cvfh_normal_max_points 64; ci: 7 CVFH, 8 CESF and 5 OUR-CVFH
// estimates moved, 3, 4 and 4 of 10 correct as before; demo: 3 CVFH and 3
// CESF, 1 and 2 of 4 as before), and when PPF took each reference point's
// partners from the scene at the model's sampling (ppf.scene_partner_steps
// 2; ci: every PPF estimate moved, 8 -> 9 of 10, image 0 now correct; demo
// has no PPF). A change that alters results on purpose updates those files and says why in its
// commit.
#include <gtest/gtest.h>

#include <map>
#include <nlohmann/json.hpp>

#include "cli_test_util.h"

namespace {

std::map<std::string, nlohmann::json> by_key(const std::string& path) {
  std::map<std::string, nlohmann::json> m;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) {
      const auto j = nlohmann::json::parse(line);
      m[j.at("key").get<std::string>()] = j;
    }
  return m;
}

class RecordsIdentical : public ::testing::TestWithParam<std::string> {};

TEST_P(RecordsIdentical, PosesErrorsAndStatusesMatchTheRecordsFromBeforeTheRefactor) {
  const std::string src = POSEBENCH_SOURCE_DIR, name = GetParam();
  const auto expected = by_key(src + "/tests/data/expected_records/" + name + ".jsonl");
  ASSERT_FALSE(expected.empty());
  pbcli::TempDir tmp;
  const auto r = pbcli::run("run configs/experiments/" + name + ".yaml --jobs 2 -q --out '" + tmp.path +
                                "/r' --scenes '" + tmp.path + "/scenes' --cache '" + tmp.path + "/cache'",
                            src);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto got = by_key(tmp.path + "/r/records.jsonl");
  ASSERT_EQ(got.size(), expected.size());
  int compared = 0;
  for (const auto& [key, want] : expected) {
    const auto it = got.find(key);
    ASSERT_NE(it, got.end()) << "no record " << key;
    for (const auto& [field, value] : want.items()) {
      ASSERT_TRUE(it->second.contains(field)) << key << ": no " << field;
      EXPECT_EQ(it->second.at(field), value) << key << ": " << field;
      ++compared;
    }
  }
  std::printf("%s: %zu records, %d fields identical to the expected records\n", name.c_str(), got.size(), compared);
}

INSTANTIATE_TEST_SUITE_P(Experiments, RecordsIdentical, ::testing::Values("ci", "demo"),
                         [](const auto& info) { return info.param; });

}  // namespace
