// The pipeline benchmark's table (`posebench bench-pipeline`): per scene
// set x descriptor x refinement, the median time of each stage of the online
// computation over the images, the total's median and 90th percentile, and
// the robustness (k of n with a 95% Wilson interval) the times were bought
// with, against a per-scenario time budget. Built from the trial records of
// a run, so the numbers are those the runner recorded. PCL-free.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

#include "eval/record.h"
#include "eval/stats.h"

namespace pb {

struct BenchRow {
  std::string scene, scenario, descriptor, refinement;
  int trials = 0;                 // records of the row
  int ok = 0;                     // status ok
  Proportion correct;             // thesis judgement, over records with a ground truth
  // Medians over the row's records with times (seconds): preprocess,
  // hypothesize (describe + match + group + initial pose), refine, verify.
  double preprocess_s = 0, hypothesize_s = 0, refine_s = 0, verify_s = 0;
  double total_s = 0, total_p90_s = 0;  // the whole online computation
  double hypotheses = 0;          // median hypothesis count
  double budget_s = 0;            // the scenario's budget (0 = none)
  bool within_budget() const { return budget_s > 0 && total_s <= budget_s; }
};

struct BenchTable {
  std::vector<BenchRow> rows;     // in the records' first-appearance order
  nlohmann::json host;            // machine and run facts (cpu, cores, threads, date)
  // The recognition settings the config gives over the defaults, so a table
  // says what it timed: {"all": the experiment's settings, SCENE: that scene
  // set's own}; empty ones left out (every resolved value is in the records'
  // settings_resolved).
  nlohmann::json settings = nlohmann::json::object();
};

// Budgets per scenario in seconds (issue targets: table 0.033, warehouse 0.1).
BenchTable bench_table(const std::vector<TrialRecord>& records, const std::map<std::string, double>& budgets_s);

nlohmann::json bench_json(const BenchTable& t);
std::string bench_markdown(const BenchTable& t);

}  // namespace pb
