// Shared by the runner's unit tests (test_runner_store.cpp, test_runner_shard.cpp).
#pragma once

#include <string>

#include "eval/record.h"

namespace pbtest {

// A complete record (every key required for its status) with this key,
// status and, with status ok, score.
inline pb::TrialRecord record(const std::string& key, const std::string& status, double score = 0.9) {
  pb::TrialRecord r;
  r.key = key;
  r.scene = "table";
  r.scenario = "table";
  r.dataset = "d";
  r.split = "test";
  r.descriptor = "fpfh";
  r.refinement = "icp";
  r.status = status;
  if (status == "ok") {  // the keys required with status ok
    r.wall_s = 0.5;
    r.obj_id = 2;
    r.settings_resolved = nlohmann::json::object();
    r.train_s = 0.1;
    r.train_from_cache = true;
    r.times = pb::StageTimesRecord{};
    r.hypotheses = 1;
    r.estimate = pb::PoseRecord{{1, 0, 0, 0, 1, 0, 0, 0, 1}, {0, 0, 700}};
    r.score = score;
    r.inliers = 120;
  }
  return r;
}

}  // namespace pbtest
