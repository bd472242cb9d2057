#include "eval/judge.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pb {

InstanceJudgement judge(const Pose& est, const std::vector<Pose>& gts, const std::vector<Pose>& symmetries,
                        const ThesisThresholds& thr, const std::vector<bool>* taken) {
  InstanceJudgement out;
  double best = std::numeric_limits<double>::infinity();
  for (size_t g = 0; g < gts.size(); ++g) {
    if (taken && (*taken)[g]) continue;
    const ThesisJudgement j = thesis_judge(est, gts[g], symmetries, thr);
    double fit = std::max(j.errors.translation_mm / thr.translation_mm, j.errors.rotation / thr.rotation);
    if (std::isnan(fit)) fit = std::numeric_limits<double>::infinity();  // a non-finite pose fits none
    if (out.gt < 0 || fit < best) {
      best = fit;
      out.gt = static_cast<int>(g);
      out.judged = j;
    }
  }
  return out;
}

std::vector<InstanceJudgement> judge_in_order(const std::vector<Pose>& estimates, const std::vector<Pose>& gts,
                                              const std::vector<Pose>& symmetries, const ThesisThresholds& thr) {
  std::vector<InstanceJudgement> out;
  std::vector<bool> taken(gts.size(), false);
  for (const Pose& est : estimates) {
    out.push_back(judge(est, gts, symmetries, thr, &taken));
    if (out.back().gt >= 0 && out.back().judged.correct) taken[static_cast<size_t>(out.back().gt)] = true;
  }
  return out;
}

}  // namespace pb
