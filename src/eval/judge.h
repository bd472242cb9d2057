// The one judge of pose estimates against an image's ground truth, used by
// `recognize`, `run` (and so `advise`, which runs trials) and the records'
// instances. Every instance of the object in the image is a candidate, as in
// BOP's matching: an estimate is judged against the instance it fits best,
// and with several estimates (in rank order) an instance is taken by at most
// one correct estimate.
//
// "Fits best" is the smallest max(translation / thr.translation_mm,
// rotation / thr.rotation) of the thesis's symmetry-aware errors
// (eval/errors.h), so a correct match (both ratios below 1) is always
// preferred; ties go to the lower instance index.
#pragma once

#include <vector>

#include "core/types.h"
#include "eval/errors.h"

namespace pb {

struct InstanceJudgement {
  int gt = -1;              // index into the candidates of the instance judged against; -1 = none
  ThesisJudgement judged;   // the errors against it and whether they are correct
};

// One estimate against the candidates (the object's instances' T_cam_model),
// skipping those marked in `taken` (same size as gts, or null for none).
InstanceJudgement judge(const Pose& est, const std::vector<Pose>& gts, const std::vector<Pose>& symmetries,
                        const ThesisThresholds& thr, const std::vector<bool>* taken = nullptr);

// Estimates in rank order: each is judged against the instances no earlier
// correct estimate took; a correct estimate takes its instance.
std::vector<InstanceJudgement> judge_in_order(const std::vector<Pose>& estimates, const std::vector<Pose>& gts,
                                              const std::vector<Pose>& symmetries, const ThesisThresholds& thr);

}  // namespace pb
