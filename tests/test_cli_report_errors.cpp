// `posebench report` reads records strictly: a misspelt key in records.jsonl
// is exit code 2 with one message naming the file, the line and the key (not
// a report in which that record silently got a default status).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cli_test_util.h"

namespace {

nlohmann::json record(const std::string& key) {
  return {{"key", key},        {"scene", "table_synthetic"}, {"scenario", "table"}, {"dataset", "d"},
          {"split", "test"},   {"scene_id", 1},              {"im_id", 0},          {"descriptor", "fpfh"},
          {"refinement", "icp"}, {"params", nlohmann::json::object()}, {"added_noise_mm", 0.0},
          {"settings", nlohmann::json::object()}, {"seed", 3}, {"status", "timeout"}, {"correct", false},
          {"message", "exceeded the time limit of 300 s"}};
}

TEST(CliReport, MisspeltKeyInRecordsIsExit2NamingFileLineAndKey) {
  pbcli::TempDir tmp;
  const std::string dir = tmp.path + "/r";
  pbcli::write_file(dir + "/experiment.json", R"({"name": "x", "hash": "h", "descriptors": ["fpfh"],
    "refinements": ["icp"], "scenes": [{"name": "table_synthetic", "scenario": "table"}]})");
  nlohmann::json bad = record("b");
  bad.erase("status");
  bad["statsu"] = "timeout";
  pbcli::write_file(dir + "/records.jsonl", record("a").dump() + "\n" + bad.dump() + "\n");
  const auto r = pbcli::run("report '" + dir + "' --format md", tmp.path);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find(dir + "/records.jsonl"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("line 2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("statsu"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");  // no partial report

  // The same file with the key spelt right reports.
  pbcli::write_file(dir + "/records.jsonl", record("a").dump() + "\n" + record("b").dump() + "\n");
  const auto ok = pbcli::run("report '" + dir + "' --format md", tmp.path);
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("Records: 2"), std::string::npos) << ok.out;
}

TEST(CliSchema, RecordSchemaListsRequiredAndOptionalKeys) {
  pbcli::TempDir tmp;
  const auto r = pbcli::run("schema record", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["fields"]["status"]["required"], true);
  EXPECT_EQ(j["fields"]["estimate"]["required"], "when_ok");
  EXPECT_EQ(j["fields"]["errors"]["required"], "when_gt");
  EXPECT_EQ(j["fields"]["gt"]["required"], false);
  EXPECT_EQ(j["fields"]["estimate"]["fields"]["R"]["type"], "array");
  EXPECT_EQ(j["fields"]["judgements"]["values"]["fields"]["correct"]["type"], "boolean");
  const auto bad = pbcli::run("schema recrod", tmp.path);
  EXPECT_EQ(bad.code, 2);
}

}  // namespace
