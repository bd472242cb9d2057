// Refactors change no result: every record of configs/experiments/ci.yaml
// and demo.yaml has the same status, estimated pose, errors (thesis and BOP),
// correctness, score, inliers, hypothesis count and ground truth, bit for
// bit (exact JSON numbers), as tests/data/expected_records/*.jsonl. A change
// that alters results on purpose rewrites those files from a run of the two
// experiments (the same fields per record) and says in its commit message
// why, with the correct count per method before and after (git log of the
// files has every such change).
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
