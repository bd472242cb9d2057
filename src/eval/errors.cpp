#include "eval/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/rotation.h"

namespace pb {

ThesisThresholds thesis_thresholds(const std::string& scenario) {
  ThesisThresholds t;
  if (scenario == "table") {
    t.translation_mm = 50.0;
  } else if (scenario == "warehouse") {
    t.translation_mm = 100.0;
  } else {
    throw InputError("", "scenario",
                     "unknown scenario '" + scenario + "' (expected table or warehouse)");
  }
  t.rotation = 0.05;
  return t;
}

double quaternion_rotation_error(const Mat3& Ra, const Mat3& Rb) {
  const Eigen::Quaterniond p = to_quaternion(Ra);
  const Eigen::Quaterniond q = to_quaternion(Rb);
  const double d = std::min(1.0, std::abs(p.dot(q)));
  return 1.0 - d;
}

namespace {

struct Candidate {
  double te, re;
  double cost;  // max(te / thr_t, re / thr_r)
  bool under;   // te < thr_t && re < thr_r
};

}  // namespace

ThesisErrors thesis_errors(const Pose& T_est, const Pose& T_gt, const std::vector<Pose>& symmetries,
                           const ThesisErrorOptions& opt) {
  const ThesisThresholds& thr = opt.thresholds;
  static const std::vector<Pose> kIdentity{Pose::identity()};
  const std::vector<Pose>& syms = symmetries.empty() ? kIdentity : symmetries;

  std::vector<Candidate> c(syms.size());
  bool any_under = false;
  const Eigen::Quaterniond p = to_quaternion(T_est.R);
  for (size_t i = 0; i < syms.size(); ++i) {
    const Mat3 Rg = T_gt.R * syms[i].R;
    const Vec3 tg = T_gt.R * syms[i].t + T_gt.t;
    c[i].te = (T_est.t - tg).norm();
    c[i].re = 1.0 - std::min(1.0, std::abs(p.dot(to_quaternion(Rg))));
    c[i].cost = std::max(c[i].te / thr.translation_mm, c[i].re / thr.rotation);
    c[i].under = c[i].te < thr.translation_mm && c[i].re < thr.rotation;
    any_under = any_under || c[i].under;
  }
  double cmin = std::numeric_limits<double>::infinity();
  for (const Candidate& k : c) {
    if (any_under && !k.under) continue;
    cmin = std::min(cmin, k.cost);
  }
  int best = -1;
  for (size_t i = 0; i < c.size(); ++i) {
    const Candidate& k = c[i];
    if (any_under && !k.under) continue;
    if (!(k.cost <= cmin + 1e-9)) continue;
    if (best < 0 || k.re < c[best].re || (k.re == c[best].re && k.te < c[best].te)) {
      best = static_cast<int>(i);
    }
  }
  if (best < 0) best = 0;  // only with NaN inputs: report the identity

  ThesisErrors e;
  e.symmetry = best;
  e.translation_mm = c[best].te;
  e.rotation = c[best].re;
  e.rotation_deg = rotation_angle_deg(T_est.R, T_gt.R * syms[best].R);
  e.translation_mm_plain = (T_est.t - T_gt.t).norm();
  e.rotation_plain = quaternion_rotation_error(T_est.R, T_gt.R);
  e.rotation_deg_plain = rotation_angle_deg(T_est.R, T_gt.R);
  return e;
}

bool thesis_correct(const ThesisErrors& e, const ThesisThresholds& thr) {
  return e.translation_mm < thr.translation_mm && e.rotation < thr.rotation;
}

ThesisJudgement thesis_judge(const Pose& T_est, const Pose& T_gt, const std::vector<Pose>& symmetries,
                             const ThesisThresholds& thr) {
  ThesisJudgement j;
  j.errors = thesis_errors(T_est, T_gt, symmetries, {thr});
  j.correct = thesis_correct(j.errors, thr);
  return j;
}

namespace {

void mean_std(const std::vector<double>& v, double* mean, double* sd) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (v.empty()) {
    *mean = nan;
    *sd = nan;
    return;
  }
  double s = 0;
  for (double x : v) s += x;
  const double m = s / v.size();
  *mean = m;
  if (v.size() < 2) {
    *sd = nan;
    return;
  }
  double ss = 0;
  for (double x : v) ss += (x - m) * (x - m);
  *sd = std::sqrt(ss / (v.size() - 1));
}

}  // namespace

ThesisAggregate thesis_aggregate(const std::vector<ThesisTrial>& trials, const ThesisThresholds& thr) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ThesisAggregate a;
  a.trials = static_cast<int>(trials.size());
  std::vector<double> te, re, rd;
  double time_sum = 0;
  for (const ThesisTrial& t : trials) {
    if (t.time_s >= 0) {
      ++a.timed;
      time_sum += t.time_s;
    }
    if (t.has_pose && thesis_correct(t.errors, thr)) {
      ++a.correct;
      te.push_back(t.errors.translation_mm);
      re.push_back(t.errors.rotation);
      rd.push_back(t.errors.rotation_deg);
    }
  }
  a.robustness = a.trials > 0 ? static_cast<double>(a.correct) / a.trials : nan;
  mean_std(te, &a.translation_mean_mm, &a.translation_std_mm);
  mean_std(re, &a.rotation_mean, &a.rotation_std);
  mean_std(rd, &a.rotation_deg_mean, &a.rotation_deg_std);
  a.time_mean_s = a.timed > 0 ? time_sum / a.timed : nan;
  return a;
}

}  // namespace pb
