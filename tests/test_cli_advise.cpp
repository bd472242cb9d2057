// posebench advise (issue 9) on a mesh from ../shared/models: a ranked table
// with k of n and 95% intervals, and OUT/best.yaml that `posebench run`
// turns into the same records as the advisor's top cell; bad input is exit 2
// naming the file and the field.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>

#include "cli_test_util.h"

namespace {

const std::string kBunny = std::string(POSEBENCH_SOURCE_DIR) + "/../shared/models/bunny.obj";

std::map<std::string, nlohmann::json> records(const std::string& file) {
  std::map<std::string, nlohmann::json> m;
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) {
      const auto j = nlohmann::json::parse(line);
      m[j["key"]] = j;
    }
  return m;
}

TEST(Advise, RanksWithIntervalsAndItsBestYamlReproducesTheTopCell) {
  if (!std::filesystem::exists(kBunny)) GTEST_SKIP() << "../shared/models/bunny.obj is absent: nothing to advise on";
  pbcli::TempDir tmp;
  // The bunny file is in decimetres (about 2 units across) with y up.
  const auto r = pbcli::run("advise " + kBunny +
                                " --mesh-scale 100 --up +y --images 4 --methods ppf,fpfh --refinements icp "
                                "--length-factors 0.7,1 --out adv --jobs 2 -q",
                            tmp.path);
  ASSERT_EQ(r.code, 0) << r.err << r.out;
  EXPECT_NE(r.out.find("bunny: diameter 197.69"), std::string::npos) << r.out;
  // Four cells, each "k/4 [lo, hi]".
  const std::regex row(R"((\d)/4\s+\[(\d\.\d\d), (\d\.\d\d)\])");
  std::vector<int> ks;
  for (auto it = std::sregex_iterator(r.out.begin(), r.out.end(), row); it != std::sregex_iterator(); ++it) {
    ks.push_back(std::stoi((*it)[1]));
    EXPECT_LE(std::stod((*it)[2]), std::stod((*it)[3]));
  }
  ASSERT_EQ(ks.size(), 4u) << r.out;
  EXPECT_TRUE(std::is_sorted(ks.rbegin(), ks.rend())) << r.out;  // most correct first (no budget given)
  ASSERT_TRUE(std::filesystem::exists(tmp.path + "/adv/best.yaml"));

  const auto best = pbcli::run("run adv/best.yaml --out best --jobs 2 -q", tmp.path);
  ASSERT_EQ(best.code, 0) << best.err;
  const auto all = records(tmp.path + "/adv/run/records.jsonl");
  const auto mine = records(tmp.path + "/best/records.jsonl");
  ASSERT_EQ(mine.size(), 4u);
  int k = 0;
  for (const auto& [key, rec] : mine) {
    ASSERT_TRUE(all.count(key)) << key << ": not a trial of the advisor's run";
    EXPECT_EQ(rec.value("estimate", nlohmann::json()), all.at(key).value("estimate", nlohmann::json())) << key;
    k += rec.value("correct", false);
  }
  EXPECT_EQ(k, ks.front()) << "the best config's robustness is not the advisor's top one";
}

TEST(Advise, BadInputIsExit2NamingTheFileAndField) {
  pbcli::TempDir tmp;
  auto r = pbcli::run("advise missing.obj --out adv -q", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("missing.obj"), std::string::npos) << r.err;
  if (!std::filesystem::exists(kBunny)) GTEST_SKIP() << "../shared/models/bunny.obj is absent";
  r = pbcli::run("advise " + kBunny + " --out adv -q", tmp.path);  // 2 mm across when read as mm
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("field 'size'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--mesh-scale"), std::string::npos) << r.err;
  r = pbcli::run("advise " + kBunny + " --mesh-scale 100 --scenario warehouse --out adv -q", tmp.path);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--scenario"), std::string::npos) << r.err;
}

}  // namespace
