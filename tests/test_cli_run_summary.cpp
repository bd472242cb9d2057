// posebench run's account of itself (INTERFACES.md section 2): every
// invocation that runs trials appends one line to OUT/runs.jsonl, and
// --json-summary FILE writes the same object (also when nothing ran). A
// small run: the counts add up, a resumed run that finds everything recorded
// says so and adds no line. The records of an experiment with `judgements:`
// carry judgements.NAME on every judged pose.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <nlohmann/json.hpp>
#include <map>
#include <regex>
#include <vector>

#include "cli_test_util.h"
#include "test_cli_run_scene.h"

namespace {

// 3 images x 1 descriptor: 3 trials; a second judgement by the half turn
// about the LS5's vertical axis.
std::string experiment_yaml(const std::string& scene_cfg) {
  return "name: summarytest\nseed: 3\nobject: ls5\nscenes:\n  - name: table_small\n    generate: " + scene_cfg +
         "\n    scenario: table\ndescriptors: [cvfh]\nrefinements: [icp]\nsettings:\n  views: {views: 4}\n"
         "judgements:\n  halfturn:\n    symmetries_discrete:\n"
         "      - [[-1, 0, 0, 0], [0, -1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n";
}

std::vector<nlohmann::json> lines(const std::string& path) {
  std::vector<nlohmann::json> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) out.push_back(nlohmann::json::parse(line));
  return out;
}

// The summary's trial counts, its status counts adding up to those run.
void expect_counts(const nlohmann::json& s, int total, int already, int ran) {
  EXPECT_EQ(s.at("total"), total) << s.dump();
  EXPECT_EQ(s.at("already_recorded"), already) << s.dump();
  EXPECT_EQ(s.at("ran"), ran) << s.dump();
  int n = 0;
  for (const auto& [status, c] : s.at("status_counts").items()) n += c.get<int>();
  EXPECT_EQ(n, ran) << s.dump();
}

TEST(CliRunSummary, RunsJsonlAndJsonSummaryCountTheTrials) {
  pbcli::TempDir tmp;
  pbcli::write_file(tmp.path + "/scene.yaml", pbcli::kSmallTableScene);
  pbcli::write_file(tmp.path + "/exp.yaml", experiment_yaml(tmp.path + "/scene.yaml"));
  setenv("OMP_NUM_THREADS", "1", 1);  // inherited by posebench and its workers
  const std::string common = "--out r --cache '" + tmp.path + "/cache' --scenes '" + tmp.path + "/scenes' -q";

  const auto a = pbcli::run("run exp.yaml --jobs 2 --json-summary s1.json " + common, tmp.path);
  ASSERT_EQ(a.code, 0) << a.err;
  const auto s1 = nlohmann::json::parse(pbcli::slurp(tmp.path + "/s1.json"));
  expect_counts(s1, 3, 0, 3);
  EXPECT_EQ(s1.at("jobs"), 2);
  EXPECT_EQ(s1.at("omp_threads"), 1);
  EXPECT_GE(s1.at("host_cores").get<int>(), 1);
  EXPECT_GT(s1.at("wall_s").get<double>(), 0.0);
  EXPECT_TRUE(s1.at("load15_end").is_number());
  EXPECT_TRUE(std::regex_match(s1.at("started").get<std::string>(),
                               std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)")))
      << s1.at("started");

  // runs.jsonl: one line, the same object.
  const auto runs = lines(tmp.path + "/r/runs.jsonl");
  ASSERT_EQ(runs.size(), 1u);
  for (const auto& [k, v] : runs[0].items()) EXPECT_EQ(s1.at(k), v) << k;
  for (const char* k : {"started", "wall_s", "total", "already_recorded", "ran", "status_counts", "jobs",
                        "omp_threads", "load15_end", "host_cores"})
    EXPECT_TRUE(runs[0].contains(k)) << k;

  // The records: as many as ran, each status counted; every judged pose is
  // also judged by the experiment's extra symmetry set.
  const auto recs = lines(tmp.path + "/r/records.jsonl");
  ASSERT_EQ(recs.size(), 3u);
  std::map<std::string, int> statuses;
  int judged = 0;
  for (const auto& r : recs) {
    ++statuses[r.at("status").get<std::string>()];
    if (r.at("status") == "ok" && r.contains("gt")) {
      ASSERT_TRUE(r.contains("judgements")) << r.dump();
      EXPECT_TRUE(r["judgements"]["halfturn"]["correct"].is_boolean());
      EXPECT_TRUE(r["judgements"]["halfturn"]["translation_mm"].is_number());
      ++judged;
    }
  }
  EXPECT_GT(judged, 0);
  for (const auto& [status, n] : statuses) EXPECT_EQ(s1["status_counts"].value(status, 0), n) << status;

  // Resumed with everything recorded: nothing ran, no runs.jsonl line, but
  // the summary file says so.
  const auto b = pbcli::run("run exp.yaml --jobs 1 --json-summary s2.json " + common, tmp.path);
  ASSERT_EQ(b.code, 0) << b.err;
  const auto s2 = nlohmann::json::parse(pbcli::slurp(tmp.path + "/s2.json"));
  expect_counts(s2, 3, 3, 0);
  EXPECT_EQ(lines(tmp.path + "/r/runs.jsonl").size(), 1u);

  // The records read back strictly (the reporter's reader).
  const auto rep = pbcli::run("report r --format md", tmp.path);
  EXPECT_EQ(rep.code, 0) << rep.err;
  EXPECT_NE(rep.out.find("Records: 3"), std::string::npos) << rep.out;
  EXPECT_NE(rep.out.find("robustness, judged by halfturn"), std::string::npos) << rep.out;
}

}  // namespace

namespace {

// The lines of `text` that are log events named `event` (TIME LEVEL EVENT ...).
std::vector<std::string> events(const std::string& text, const std::string& level, const std::string& event) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string line;
  const std::regex re("^[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:.]+ " + level + " " + event + "( .*)?$");
  while (std::getline(ss, line))
    if (std::regex_match(line, re)) out.push_back(line);
  return out;
}

}  // namespace

// -v: one debug log line per finished trial with its record's key, status
// and correctness; -q: nothing on stderr; the default: what the run does
// (a resumed run says so) but no trial lines.
TEST(CliRunSummary, LogLevelsAndOneLinePerTrial) {
  pbcli::TempDir tmp;
  const auto r = pbcli::run_small_experiment(tmp.path, "logtest", "[cvfh]");  // -q
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  // Again with -v into a fresh folder: a line per trial.
  const std::string common = " --cache cache --scenes scenes";
  const auto v = pbcli::run("run exp.yaml --out v -v" + common, tmp.path);
  ASSERT_EQ(v.code, 0) << v.err;
  const auto trials = events(v.err, "debug", "trial");
  std::map<std::string, nlohmann::json> recs;
  for (const auto& j : lines(tmp.path + "/v/records.jsonl")) recs[j["key"]] = j;
  ASSERT_EQ(trials.size(), recs.size()) << v.err;
  for (const auto& [key, j] : recs) {
    const std::string want = "key=" + (key.find_first_of(" \"'=") == std::string::npos ? key : nlohmann::json(key).dump()) +
                             " status=" + j["status"].get<std::string>() + " correct=" + (j.value("correct", false) ? "true" : "false");
    EXPECT_EQ(std::count_if(trials.begin(), trials.end(), [&](const std::string& l) { return l.find(want) != std::string::npos; }), 1)
        << want << "\n" << v.err;
  }
  // The default level: a resume line, no trial lines.
  const auto d = pbcli::run("run exp.yaml --out v" + common, tmp.path);
  ASSERT_EQ(d.code, 0) << d.err;
  EXPECT_EQ(events(d.err, "info", "resume").size(), 1u) << d.err;
  EXPECT_EQ(events(d.err, "debug", "trial").size(), 0u) << d.err;
}
