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

#include <cmath>
#include <vector>

#include "core/types.h"
#include "eval/errors.h"

namespace pb {

// The greedy matching of BOP's toolkit (match_poses), which the judge below
// and `score` (eval/bop_metrics_scores.cpp) share: estimates in rank order,
// each paired with the instance that no earlier estimate took and that has
// the smallest fit(e, g) (ties to the lower index; a NaN or infinite fit
// pairs with nothing), and taking it when accept(e, g). Returns each
// estimate's instance (-1 = none) and whether it took it.
struct InstanceMatch {
  int gt = -1;
  bool taken = false;
};
template <class Fit, class Accept>
std::vector<InstanceMatch> match_in_order(size_t estimates, size_t instances, Fit fit, Accept accept) {
  std::vector<InstanceMatch> out(estimates);
  std::vector<bool> taken(instances, false);
  for (size_t e = 0; e < estimates; ++e) {
    double best = 0;
    for (size_t g = 0; g < instances; ++g) {
      if (taken[g]) continue;
      const double f = fit(e, g);
      if (!std::isfinite(f)) continue;
      if (out[e].gt < 0 || f < best) {
        best = f;
        out[e].gt = static_cast<int>(g);
      }
    }
    if (out[e].gt >= 0 && accept(e, static_cast<size_t>(out[e].gt))) {
      out[e].taken = true;
      taken[static_cast<size_t>(out[e].gt)] = true;
    }
  }
  return out;
}

struct InstanceJudgement {
  int gt = -1;              // index into the candidates of the instance judged against; -1 = none
  ThesisJudgement judged;   // the errors against it and whether they are correct
};

// One estimate against the candidates (the object's instances' T_cam_model),
// skipping those marked in `taken` (same size as gts, or null for none).
InstanceJudgement judge(const Pose& est, const std::vector<Pose>& gts, const std::vector<Pose>& symmetries,
                        const ThesisThresholds& thr, const std::vector<bool>* taken = nullptr);

// Estimates in rank order (match_in_order): each is judged against the
// instances no earlier correct estimate took; a correct estimate takes its
// instance. A non-finite estimate is judged against none (gt -1).
std::vector<InstanceJudgement> judge_in_order(const std::vector<Pose>& estimates, const std::vector<Pose>& gts,
                                              const std::vector<Pose>& symmetries, const ThesisThresholds& thr);

}  // namespace pb
