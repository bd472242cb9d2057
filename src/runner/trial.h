// One trial, executed inside a worker process: load the image, add the
// trial's noise, train (or load from cache) the model, recognize, score
// against the ground truth. Returns the typed record the store keeps.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "eval/record.h"
#include "runner/experiment.h"

namespace pb {

struct TrialContext {
  std::string object;     // object name or id, resolved in each dataset
  std::string cache_dir;  // training cache ("" = none)
  Thresholds thresholds;
  bool registration_only = false;
  double perturb_deg = 10, perturb_mm = 20;
  std::vector<Judgement> judgements;  // extra symmetry sets every pose is also judged with
};

// The context line the runner sends a worker, and its reading.
nlohmann::json context_json(const ExperimentConfig& cfg, const std::string& cache_dir);
TrialContext context_from_json(const nlohmann::json& j);

// The trial part of a record (every required key but the outcome).
TrialRecord trial_record(const Trial& t);

// Runs `trial` (the record of trial_record). Never throws: failures become
// status "error" with a message.
TrialRecord run_trial(const TrialRecord& trial, const TrialContext& ctx);

}  // namespace pb
