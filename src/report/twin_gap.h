// The sim-to-real gap of an experiment that runs a real scene set and its
// twin (`posebench twin`; a scene with `twin_of: REAL`): per method the
// targets found on the real frames and on their twins, paired target by
// target, with McNemar's exact test of the discordant pairs. A target is
// found when the trial's first estimate has MSSD < 0.2 of the object's
// diameter (BOP's middle threshold); trials without BOP errors count as not
// found. PCL-free.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/record.h"
#include "eval/stats.h"

namespace pb {

struct TwinGapRow {
  std::string real_scene, twin_scene;
  std::string method;     // descriptor + refinement
  std::string condition;  // grid point and added noise ("" for the default)
  int pairs = 0;          // targets run on both sets
  int real_k = 0, twin_k = 0, both = 0, real_only = 0, twin_only = 0;
  double mcnemar_p = 1;   // two-sided exact test of real_only against twin_only
  Proportion real() const { return wilson(real_k, pairs); }
  Proportion twin() const { return wilson(twin_k, pairs); }
};

// The rows of every (real, twin) scene pair the experiment declares, in
// the order of its scenes, then method, then condition.
std::vector<TwinGapRow> twin_gap(const nlohmann::json& experiment, const std::vector<TrialRecord>& records);
// The table in Markdown ("" when there is no row).
std::string twin_gap_markdown(const std::vector<TwinGapRow>& rows);
// The same as CSV (`report --format csv` writes it to twin_gap.csv): real,
// twin, method, condition, pairs, real_k, twin_k, both, real_only,
// twin_only, mcnemar_p.
std::string twin_gap_csv(const std::vector<TwinGapRow>& rows);

}  // namespace pb
