// One trial, executed inside a worker process: load the image, add the
// trial's noise, train (or load from cache) the model, recognize, score
// against the ground truth. Returns the JSON record the store keeps.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace pb {

struct TrialContext {
  std::string object;     // object name or id, resolved in each dataset
  std::string cache_dir;  // training cache ("" = none)
  double table_translation_mm = 50, warehouse_translation_mm = 100, rotation_1mpq = 0.05;
  bool registration_only = false;
  double perturb_deg = 10, perturb_mm = 20;
};

// `trial` is the JSON form of a Trial (runner.cpp). Never throws: failures
// become status "error" with a message.
nlohmann::json run_trial(const nlohmann::json& trial, const TrialContext& ctx);

}  // namespace pb
