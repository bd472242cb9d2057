// The trial record: one typed struct shared by the runner (which writes it to
// records.jsonl), the reporter (which reads it) and the scripts (which read
// it through the schema `posebench schema record` prints). Reading is
// strict: an unknown key or a missing required key is an InputError naming
// the file, the line and the key, never a silent default. PCL-free.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/stage_times.h"
#include "core/types.h"

namespace pb {

struct PoseRecord {            // {"R": [9, row-major], "t": [3, mm]}
  std::array<double, 9> R{};
  std::array<double, 3> t{};
  static PoseRecord from(const Pose& T);
  Pose pose() const;
};

struct StageTimesRecord {      // seconds per stage of the online computation (StageTimes::each), and their sum
  StageTimes stages;
  double total = 0;
  static StageTimesRecord from(const StageTimes& t) { return {t, t.total()}; }
};

struct ThesisErrorsRecord {    // eval/errors.h, symmetry-aware, and against the GT itself ("plain")
  double translation_mm = 0, rotation_1mpq = 0, rotation_deg = 0;
  int symmetry = 0;            // index of the chosen symmetry (0 = identity)
  double translation_mm_plain = 0, rotation_1mpq_plain = 0;
};

struct BopErrorsRecord {       // eval/bop_metrics.h, bop19 settings
  double mssd_mm = 0, mspd_px = 0;
  std::vector<double> vsd;     // one per tau
  double diameter = 0;         // mm
  int image_width = 0;         // px
};

struct JudgementRecord {       // the thesis's judgement over an extra symmetry set
  bool correct = false;
  double translation_mm = 0, rotation_1mpq = 0;
};

struct InstanceRecord {        // one instance of a multi-instance trial (BOP inst_count)
  PoseRecord estimate;
  double score = 0;            // what verification ranked it by (Hypothesis::verification)
  int inliers = 0;
  // The thesis's judgement against the object's GT instances, each GT
  // matched at most once, instances in rank order; absent without GT.
  std::optional<bool> correct;
};

struct TrialRecord {
  // The trial (runner/experiment.h Trial): always present.
  std::string key, scene, scenario, dataset, split;
  int scene_id = 0, im_id = 0;
  std::string descriptor, refinement;
  // A test target's instance count (experiment `object: all` with BOP
  // test targets): recognize up to this many instances. None: one estimate.
  std::optional<int> inst_count;
  nlohmann::json params = nlohmann::json::object();    // grid point: dotted path -> value
  double added_noise_mm = 0;
  // The trial's settings: the fields that differ from the defaults, section
  // by section, with the descriptor and refinement (settings_changes_json);
  // relative lengths as "0.05d".
  nlohmann::json settings = nlohmann::json::object();
  uint64_t seed = 0;
  // The outcome. `status` is always present; the rest when the trial got
  // that far (record_schema(): "when_ok" = present in every record with
  // status ok, "when_gt" = in every record with status ok and `gt`). A trial
  // whose worker crashed or timed out has the trial, status, message and
  // correct = false only, as before the typed record.
  std::string status;          // ok | no_hypothesis | error | timeout | out_of_memory
  std::optional<bool> correct;  // the thesis's judgement: with a GT pose (false without an estimate), or a failed worker
  std::optional<double> wall_s;  // wall time of the whole trial in its worker (s); none when the worker failed
  std::optional<std::string> message;
  std::optional<int> obj_id;   // set with the trial when the experiment takes objects from test targets
  std::optional<nlohmann::json> settings_resolved;  // every field, after defaults
  std::optional<double> train_s;
  std::optional<bool> train_from_cache;
  std::optional<StageTimesRecord> times;
  std::optional<int> hypotheses;
  // With ground truth and hypotheses: the rank (0 = the chosen one) of the
  // first ranked hypothesis the thesis's judgement calls correct, -1 if none
  // is. correct_rank > 0: a correct hypothesis existed, verification chose a
  // wrong one.
  std::optional<int> correct_rank;
  std::optional<PoseRecord> init;      // registration_only: the perturbed start
  std::optional<PoseRecord> estimate;  // status ok
  // With inst_count: every instance found, best first (the first is
  // `estimate`).
  std::optional<std::vector<InstanceRecord>> instances;
  std::optional<double> score;
  std::optional<int> inliers;
  std::optional<PoseRecord> gt;        // the first instance of the object in the image
  std::optional<double> visib_fract;
  std::optional<ThesisErrorsRecord> errors;
  std::optional<BopErrorsRecord> bop;
  std::map<std::string, JudgementRecord> judgements;  // experiment `judgements:`; omitted when empty
};

void to_json(nlohmann::json& j, const TrialRecord& r);
// Strict: InputError(file, "line N: KEY", ...) for an unknown key, a missing
// required key (always required, or required for the record's status and
// ground truth) or a value of the wrong type.
TrialRecord record_from_json(const nlohmann::json& j, const std::string& file, int line);

// The schema (`posebench schema record`): {"fields": {name: {"type",
// "required": true | false | "when_ok" | "when_gt", "fields"? | "values"? |
// "free"?}}, "notes": [...]}.
nlohmann::json record_schema();

}  // namespace pb
