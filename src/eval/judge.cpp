#include "eval/judge.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pb {

namespace {

// How well a judged pose fits its instance: < 1 for a correct one.
double fit(const ThesisJudgement& j, const ThesisThresholds& thr) {
  return std::max(j.errors.translation_mm / thr.translation_mm, j.errors.rotation / thr.rotation);
}

}  // namespace

InstanceJudgement judge(const Pose& est, const std::vector<Pose>& gts, const std::vector<Pose>& symmetries,
                        const ThesisThresholds& thr, const std::vector<bool>* taken) {
  InstanceJudgement out;
  double best = std::numeric_limits<double>::infinity();
  for (size_t g = 0; g < gts.size(); ++g) {
    if (taken && (*taken)[g]) continue;
    const ThesisJudgement j = thesis_judge(est, gts[g], symmetries, thr);
    double f = fit(j, thr);
    if (std::isnan(f)) f = std::numeric_limits<double>::infinity();  // a non-finite pose fits none
    if (out.gt < 0 || f < best) {
      best = f;
      out.gt = static_cast<int>(g);
      out.judged = j;
    }
  }
  return out;
}

std::vector<InstanceJudgement> judge_in_order(const std::vector<Pose>& estimates, const std::vector<Pose>& gts,
                                              const std::vector<Pose>& symmetries, const ThesisThresholds& thr) {
  std::vector<std::vector<ThesisJudgement>> j(estimates.size());
  for (size_t e = 0; e < estimates.size(); ++e)
    for (const Pose& gt : gts) j[e].push_back(thesis_judge(estimates[e], gt, symmetries, thr));
  const std::vector<InstanceMatch> m = match_in_order(
      estimates.size(), gts.size(), [&](size_t e, size_t g) { return fit(j[e][g], thr); },
      [&](size_t e, size_t g) { return j[e][g].correct; });
  std::vector<InstanceJudgement> out(estimates.size());
  for (size_t e = 0; e < estimates.size(); ++e)
    if (m[e].gt >= 0) out[e] = {m[e].gt, j[e][static_cast<size_t>(m[e].gt)]};
  return out;
}

}  // namespace pb
