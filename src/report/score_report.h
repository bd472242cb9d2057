// What `posebench score` writes: the scores of a results file as JSON (the
// BOP toolkit's bop19_* names for the totals, plus recalls per threshold,
// per object and every scored estimate's errors) and as a Markdown table.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "eval/score.h"

namespace pb {

// {"results", "dataset", "split", "method", "targets", "images", "rows",
//  "rows_scored", "rows_not_target", "targets_count", "bop19_average_recall",
//  "bop19_average_recall_vsd" (null without VSD), "bop19_average_recall_mssd",
//  "bop19_average_recall_mspd", "bop19_average_time_per_image", "thresholds":
//  {"vsd", "vsd_tau", "mssd", "mspd"}, "recall": {"vsd" [tau][th], "mssd",
//  "mspd"}, "per_object": {OBJ_ID: {"targets", "ar", "ar_vsd", "ar_mssd",
//  "ar_mspd"}}, "errors": [{"line", "scene_id", "im_id", "obj_id", "score",
//  "gts": [{"gt_id", "mssd_mm", "mspd_px", "vsd"}]}]}
nlohmann::json score_json(const ScoreResult& r);

// One row per object and one for all targets: targets, AR_VSD, AR_MSSD,
// AR_MSPD, AR; then the counts of estimates and the mean time per image.
std::string score_markdown(const ScoreResult& r);

}  // namespace pb
