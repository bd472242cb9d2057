// posebench score: our own run's BOP CSV scores as the report scored the
// run, and a malformed results file is exit 2 naming the line and the field.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

#include "cli_test_util.h"
#include "io/bop.h"
#include "test_cli_run_scene.h"

namespace fs = std::filesystem;

namespace {

// The report.csv value of `measure` (the one method's cell).
double report_value(const std::string& report_csv, const std::string& measure) {
  std::ifstream in(report_csv);
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string f;
    while (std::getline(ss, f, ',')) c.push_back(f);
    if (c.size() >= 6 && c[3] == measure) return std::stod(c[5]);
  }
  ADD_FAILURE() << "no " << measure << " in " << report_csv;
  return -1;
}

}  // namespace

TEST(CliScore, OurOwnCsvScoresAsTheReportDid) {
  pbcli::TempDir tmp;
  auto r = pbcli::run_small_experiment(tmp.path, "scoretest", "[cvfh]");
  ASSERT_EQ(r.code, 0) << r.err;
  r = pbcli::run("report res --format csv", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;

  // The targets: each record's image and object, as the report counts them.
  nlohmann::json targets = nlohmann::json::array();
  std::string dataset, split;
  std::ifstream in(tmp.path + "/res/records.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    dataset = j["dataset"];
    split = j["split"];
    targets.push_back({{"scene_id", j["scene_id"]}, {"im_id", j["im_id"]}, {"obj_id", j["obj_id"]}, {"inst_count", 1}});
  }
  ASSERT_EQ(targets.size(), 3u);
  pbcli::write_file(tmp.path + "/targets.json", targets.dump());
  std::vector<std::string> csvs;
  for (const auto& e : fs::directory_iterator(tmp.path + "/res/bop")) csvs.push_back(e.path().string());
  ASSERT_EQ(csvs.size(), 1u);

  r = pbcli::run("score '" + csvs[0] + "' --dataset '" + dataset + "' --targets targets.json --out sc", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| all | 3 |"), std::string::npos) << r.out;
  const auto sc = nlohmann::json::parse(pbcli::slurp(tmp.path + "/sc/scores.json"));
  EXPECT_EQ(sc["split"], split);
  EXPECT_EQ(sc["targets_count"], 3);
  const std::string rep = tmp.path + "/res/report.csv";
  EXPECT_NEAR(sc["bop19_average_recall"].get<double>(), report_value(rep, "bop_ar"), 1e-5);
  EXPECT_NEAR(sc["bop19_average_recall_mssd"].get<double>(), report_value(rep, "bop_ar_mssd"), 1e-5);
  EXPECT_NEAR(sc["bop19_average_recall_mspd"].get<double>(), report_value(rep, "bop_ar_mspd"), 1e-5);
  EXPECT_NEAR(sc["bop19_average_recall_vsd"].get<double>(), report_value(rep, "bop_ar_vsd"), 1e-5);
  // Each scored estimate's MSSD is the one its record holds.
  std::set<double> recorded, scored;
  std::ifstream in2(tmp.path + "/res/records.jsonl");
  while (std::getline(in2, line)) {
    const auto j = nlohmann::json::parse(line);
    if (j.contains("bop")) recorded.insert(j["bop"]["mssd_mm"].get<double>());
  }
  for (const auto& e : sc["errors"]) scored.insert(e["gts"][0]["mssd_mm"].get<double>());
  EXPECT_FALSE(scored.empty());
  EXPECT_EQ(scored, recorded);

  // A row whose R is not a rotation: exit 2 naming the file, line and field.
  std::string text = pbcli::slurp(csvs[0]);
  const std::string bad_line = "line " + std::to_string(std::count(text.begin(), text.end(), '\n') + 1) + " R";
  text += "1,0,1,0.5,1 0 0 0 1 0 0 0 -1,0 0 500,-1\n";
  const std::string bad = tmp.path + "/bad_tablesmall-test.csv";
  pbcli::write_file(bad, text);
  r = pbcli::run("score '" + bad + "' --dataset '" + dataset + "'", tmp.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(bad_line), std::string::npos) << r.err;
  // A file name without METHOD_DATASET-SPLIT and no --split.
  pbcli::write_file(tmp.path + "/results.csv", pbcli::slurp(csvs[0]));
  r = pbcli::run("score results.csv --dataset '" + dataset + "'", tmp.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("file name"), std::string::npos) << r.err;
}

// `object: all` over BOP test targets: a trial per target with its
// inst_count; the report's BOP CSV has a row per instance (at most
// inst_count per target, ranked by score), one time per image; score reads
// it (exit 0) and counts every target.
TEST(CliScore, EveryTargetWithItsInstanceCountGoesIntoTheCsv) {
  pbcli::TempDir tmp;
  auto r = pbcli::run_small_experiment(tmp.path, "scoretest", "[ppf]");
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json targets = nlohmann::json::array();
  std::string dataset;
  std::ifstream in(tmp.path + "/res/records.jsonl");
  std::string line;
  while (std::getline(in, line)) {
    const auto j = nlohmann::json::parse(line);
    dataset = j["dataset"];
    targets.push_back({{"scene_id", j["scene_id"]}, {"im_id", j["im_id"]}, {"obj_id", j["obj_id"]}, {"inst_count", 2}});
  }
  ASSERT_EQ(targets.size(), 3u);
  pbcli::write_file(tmp.path + "/targets.json", targets.dump());
  pbcli::write_file(tmp.path + "/all.yaml", "name: all\nseed: 3\nobject: all\nscenes:\n  - name: t\n    dataset: " +
                                                dataset + "\n    targets: " + tmp.path +
                                                "/targets.json\ndescriptors: [ppf]\nrefinements: [icp]\n"
                                                "settings:\n  views: {views: 4}\n");
  r = pbcli::run("run all.yaml --out all -q --cache cache", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream rec(tmp.path + "/all/records.jsonl");
  int records = 0;
  size_t instances = 0;
  while (std::getline(rec, line)) {
    const auto j = nlohmann::json::parse(line);
    ++records;
    EXPECT_EQ(j["inst_count"], 2);
    EXPECT_EQ(j["settings"]["verify"]["max_instances"], 2);
    ASSERT_TRUE(j.contains("instances")) << line;
    ASSERT_GE(j["instances"].size(), 1u);
    ASSERT_LE(j["instances"].size(), 2u);
    EXPECT_EQ(j["instances"][0]["estimate"], j["estimate"]);  // the first is the chosen pose
    instances += j["instances"].size();
  }
  EXPECT_EQ(records, 3);
  r = pbcli::run("report all --format csv", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<std::string> csvs;
  for (const auto& e : fs::directory_iterator(tmp.path + "/all/bop")) csvs.push_back(e.path().string());
  ASSERT_EQ(csvs.size(), 1u);
  std::ifstream csv(csvs[0]);
  std::getline(csv, line);  // header
  size_t rows = 0;
  while (std::getline(csv, line)) rows += !line.empty();
  EXPECT_EQ(rows, instances);
  r = pbcli::run("score '" + csvs[0] + "' --dataset '" + dataset + "' --targets targets.json --no-vsd", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| all | 3 |"), std::string::npos) << r.out;
}


// `object: all` on a generated scene set: the set lists its own targets
// (test_targets_bop19.json, every instance visible >= 10%), so the run has a
// trial per listed (image, object) with its inst_count, and nothing else.
TEST(CliScore, ObjectAllOnAGeneratedSetRunsItsOwnTargets) {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/scene.yaml", pbcli::kSmallTableScene);
  pbcli::write_file(tmp.path + "/all.yaml",
                    "name: gen_all\nseed: 3\nobject: all\nscenes:\n  - name: table_small\n    generate: " +
                        tmp.path + "/scene.yaml\ndescriptors: [ppf]\nrefinements: [none]\n"
                                   "settings:\n  views: {views: 4}\n");
  auto r = pbcli::run("run all.yaml --out all -q --cache cache --scenes scenes", tmp.path);
  ASSERT_EQ(r.code, 0) << r.err;
  std::map<std::tuple<int, int>, int> listed, run;  // (im_id, obj_id) -> inst_count
  std::string dataset, line;
  std::ifstream rec(tmp.path + "/all/records.jsonl");
  while (std::getline(rec, line)) {
    const auto j = nlohmann::json::parse(line);
    dataset = j["dataset"];
    run[{j["im_id"].get<int>(), j["obj_id"].get<int>()}] = j["inst_count"].get<int>();
  }
  ASSERT_FALSE(dataset.empty());
  if (fs::path(dataset).is_relative()) dataset = tmp.path + "/" + dataset;  // as --scenes gave it
  for (const auto& t : pb::read_test_targets(dataset + "/test_targets_bop19.json"))
    listed[{t.im_id, t.obj_id}] = t.inst_count;
  EXPECT_EQ(run, listed);
  std::set<int> objects;
  for (const auto& [k, n] : run) objects.insert(std::get<1>(k));
  EXPECT_GE(objects.size(), 2u);  // the LS5 and a distractor kind, at least

  // A set generated before the generator wrote its targets: exit 2 naming
  // the file, with what to do.
  fs::remove(dataset + "/test_targets_bop19.json");
  r = pbcli::run("run all.yaml --out all2 -q --cache cache --scenes scenes", tmp.path);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("test_targets_bop19.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("delete the set"), std::string::npos) << r.err;
}
