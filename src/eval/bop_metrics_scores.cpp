// BOP scores (eval/bop_metrics.h): average recalls from per-image errors,
// as the toolkit's eval_calc_scores.py.
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "eval/bop_metrics.h"
#include "eval/bop_metrics_internal.h"
#include "eval/judge.h"

namespace pb {

using bop_detail::top_estimates;

namespace {

// The toolkit's match_poses for one image and object (match_in_order,
// eval/judge.h): the number of matches. err(e, p) gives the normalized
// error of estimate e's pair p; an estimate matches below `th`.
template <class ErrFn>
int count_matches(const BopImageErrors& im, const std::vector<int>& ests, double th, ErrFn err) {
  // Each estimate's error against each valid instance (infinite: no pair).
  std::vector<std::vector<double>> x(ests.size(),
                                     std::vector<double>(im.gts.size(), std::numeric_limits<double>::infinity()));
  for (size_t i = 0; i < ests.size(); ++i) {
    const BopEstimateErrors& est = im.estimates[ests[i]];
    for (const BopPairErrors& p : est.pairs)
      if (im.gts[p.gt].valid) x[i][p.gt] = err(est, p);
  }
  int n = 0;
  for (const InstanceMatch& m : match_in_order(ests.size(), im.gts.size(), [&](size_t e, size_t g) { return x[e][g]; },
                                               [&](size_t e, size_t g) { return x[e][g] < th; }))
    n += m.taken;
  return n;
}

double mean(const std::vector<double>& v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  double s = 0;
  for (double x : v) s += x;
  return s / v.size();
}

// Checks the pairs (GT index, object, diameter) and returns the number of
// VSD taus, the same for all pairs (-1 without any pair).
int validated_tau_count(const std::vector<BopImageErrors>& images) {
  int n_tau = -1;
  for (const BopImageErrors& im : images) {
    for (const BopEstimateErrors& est : im.estimates) {
      for (const BopPairErrors& p : est.pairs) {
        if (p.gt < 0 || p.gt >= static_cast<int>(im.gts.size())) {
          throw std::invalid_argument("bop_scores: scene " + std::to_string(im.scene_id) + " image " +
                                      std::to_string(im.im_id) + ": pair gt index " +
                                      std::to_string(p.gt) + " out of range");
        }
        if (im.gts[p.gt].obj_id != est.obj_id) {
          throw std::invalid_argument("bop_scores: scene " + std::to_string(im.scene_id) + " image " +
                                      std::to_string(im.im_id) + ": an estimate of object " +
                                      std::to_string(est.obj_id) + " paired with a GT of object " +
                                      std::to_string(im.gts[p.gt].obj_id));
        }
        if (!(est.diameter > 0)) {
          throw std::invalid_argument("bop_scores: object " + std::to_string(est.obj_id) +
                                      " has no positive diameter");
        }
        if (n_tau < 0) n_tau = static_cast<int>(p.vsd.size());
        if (static_cast<int>(p.vsd.size()) != n_tau) {
          throw std::invalid_argument("bop_scores: VSD errors with different numbers of taus");
        }
      }
    }
  }
  return n_tau;  // -1: no pair at all
}

}  // namespace

BopScores bop_scores(const std::vector<BopImageErrors>& images, const BopScoreOptions& opt) {
  int n_tau = validated_tau_count(images);
  if (opt.vsd_tau_count >= 0) {
    if (n_tau >= 0 && n_tau != opt.vsd_tau_count) {
      throw std::invalid_argument("bop_scores: VSD errors with " + std::to_string(n_tau) + " taus, expected " +
                                  std::to_string(opt.vsd_tau_count));
    }
    n_tau = opt.vsd_tau_count;
  }
  if (n_tau < 0) n_tau = 0;

  BopScores s;
  std::vector<std::vector<long>> tp_vsd(n_tau, std::vector<long>(opt.vsd_thresholds.size(), 0));
  std::vector<long> tp_mssd(opt.mssd_thresholds.size(), 0), tp_mspd(opt.mspd_thresholds.size(), 0);

  for (const BopImageErrors& im : images) {
    std::map<int, int> valid_count;  // obj_id -> targets in this image
    for (const BopTarget& g : im.gts)
      if (g.valid) ++valid_count[g.obj_id];
    std::vector<double> scores;
    std::vector<int> objs;
    for (const BopEstimateErrors& e : im.estimates) {
      scores.push_back(e.score);
      objs.push_back(e.obj_id);
    }
    const double width_factor = 640.0 / im.image_width;
    for (const auto& [obj_id, k] : valid_count) {
      s.targets += k;
      const std::vector<int> ests = top_estimates(scores, objs, obj_id, k);
      s.estimates += static_cast<int>(ests.size());
      for (size_t t = 0; t < opt.mssd_thresholds.size(); ++t) {
        tp_mssd[t] += count_matches(im, ests, opt.mssd_thresholds[t],
                                    [](const BopEstimateErrors& e, const BopPairErrors& p) {
                                      return p.mssd_mm / e.diameter;
                                    });
      }
      for (size_t t = 0; t < opt.mspd_thresholds.size(); ++t) {
        tp_mspd[t] += count_matches(im, ests, opt.mspd_thresholds[t],
                                    [&](const BopEstimateErrors&, const BopPairErrors& p) {
                                      return width_factor * p.mspd_px;
                                    });
      }
      for (int tau = 0; tau < n_tau; ++tau) {
        for (size_t t = 0; t < opt.vsd_thresholds.size(); ++t) {
          tp_vsd[tau][t] += count_matches(im, ests, opt.vsd_thresholds[t],
                                          [tau](const BopEstimateErrors&, const BopPairErrors& p) {
                                            return p.vsd[tau];
                                          });
        }
      }
    }
  }

  auto recall = [&](long tp) { return s.targets > 0 ? static_cast<double>(tp) / s.targets : 0.0; };
  std::vector<double> all_vsd;
  s.recall_vsd.assign(n_tau, {});
  for (int tau = 0; tau < n_tau; ++tau) {
    for (long tp : tp_vsd[tau]) {
      s.recall_vsd[tau].push_back(recall(tp));
      all_vsd.push_back(recall(tp));
    }
  }
  for (long tp : tp_mssd) s.recall_mssd.push_back(recall(tp));
  for (long tp : tp_mspd) s.recall_mspd.push_back(recall(tp));
  s.ar_vsd = mean(all_vsd);
  s.ar_mssd = mean(s.recall_mssd);
  s.ar_mspd = mean(s.recall_mspd);
  if (std::isnan(s.ar_vsd)) {
    s.ar = 0.5 * (s.ar_mssd + s.ar_mspd);
  } else {
    s.ar = (s.ar_vsd + s.ar_mssd + s.ar_mspd) / 3.0;
  }
  return s;
}

}  // namespace pb
