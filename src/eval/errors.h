// The thesis's pose errors and scores (thesis 2.5 and the introduction of
// chapter 4), symmetry-aware.
//
// For an estimate T_e = (R_e, t_e) and ground truth T_g = (R_g, t_g):
//   translation error  ||t_e - t_g||                    (mm)
//   rotation error     1 - |p.q|, p and q the unit quaternions of R_e, R_g
//                      (= 1 - cos(angle / 2); 0.05 is about 36.4 degrees)
// Symmetry-aware: for each symmetry S of the model (eval/symmetry.h) the
// ground truth may equally be T_g * S = (R_g S.R, R_g S.t + t_g). Both errors
// are taken for the SAME S (never minimized separately, which could pair the
// rotation of one symmetry with the translation of another). S is chosen as:
//   1. if some S has both errors under the thresholds, only those S compete;
//   2. among them, the S minimizing max(translation / thr_t, rotation / thr_r);
//   3. among S within 1e-9 of that minimum, the smallest rotation error, then
//      the smallest translation error.
// Hence thesis_correct(errors, thr) with the thresholds used here is exactly
// "there is a symmetry S for which both errors are under the thresholds",
// which is how the thesis judged the LS5 (near-symmetric about its vertical
// axis) and the milk carton (correct when its faces lie on the true faces).
// When every S has S.t = 0 (symmetry axes through the model origin, as for
// every posebench model) the translation error does not depend on S and the
// reported rotation error is the minimum over the symmetry set.
#pragma once

#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

// The thesis's correctness thresholds for one scenario.
struct ThesisThresholds {
  double translation_mm = 50.0;  // correct needs translation error < this (mm); table 50, warehouse 100
  double rotation = 0.05;        // correct needs 1 - |p.q| < this (about 36.4 degrees)
};

// "table" -> {50 mm, 0.05}, "warehouse" -> {100 mm, 0.05}; any other name is
// an InputError (field "scenario").
ThesisThresholds thesis_thresholds(const std::string& scenario);

struct ThesisErrorOptions {
  // The thresholds used to choose the symmetry (see above); use the
  // scenario's, the same that thesis_correct will be given.
  ThesisThresholds thresholds;
};

struct ThesisErrors {
  double translation_mm = 0;  // ||t_e - (R_g S.t + t_g)|| for the chosen S (mm)
  double rotation = 0;        // 1 - |p.q| against R_g S.R for the chosen S, in [0, 1]
  double rotation_deg = 0;    // angle of R_e^T R_g S.R in degrees, in [0, 180]
  int symmetry = 0;           // index of the chosen S in the symmetry set (0 = identity)
  // The same errors against T_g itself (S = identity), for diagnostics.
  double translation_mm_plain = 0;
  double rotation_plain = 0;
  double rotation_deg_plain = 0;
};

// 1 - |p.q| of two rotation matrices (converted to unit quaternions).
double quaternion_rotation_error(const Mat3& Ra, const Mat3& Rb);

// The errors of T_est (= T_cam_model estimated) against T_gt. `symmetries`
// is the model's symmetry set (symmetry_transformations); an empty set is
// treated as {identity}.
ThesisErrors thesis_errors(const Pose& T_est, const Pose& T_gt, const std::vector<Pose>& symmetries,
                           const ThesisErrorOptions& opt = {});

// translation_mm < thr.translation_mm && rotation < thr.rotation (strict, as
// in the thesis).
bool thesis_correct(const ThesisErrors& e, const ThesisThresholds& thr);

// The thesis's judgement of one estimate over one symmetry set: thesis_errors
// with the symmetry chosen by `thr`, and thesis_correct with the same `thr`.
// The runner judges every pose with the model's own symmetry set and with
// each extra set of the experiment's `judgements:` (e.g. the milk carton's
// faces on faces, configs/thesis/table_4_5.yaml).
struct ThesisJudgement {
  ThesisErrors errors;
  bool correct = false;
};
ThesisJudgement thesis_judge(const Pose& T_est, const Pose& T_gt, const std::vector<Pose>& symmetries,
                             const ThesisThresholds& thr);

// One trial (one estimate of the object in one image) for the aggregates.
struct ThesisTrial {
  bool has_pose = false;  // false for no_hypothesis, timeout or error: counts as not correct
  ThesisErrors errors;    // used only when has_pose
  double time_s = -1.0;   // the whole online computation for the image (s); < 0 = unknown
};

// The thesis's scores of a list of trials. Values that are undefined (no
// trials, no correct trial, fewer than two correct trials for a standard
// deviation, no timed trial) are NaN.
struct ThesisAggregate {
  int trials = 0;               // number of trials
  int correct = 0;              // trials with a pose that thesis_correct accepts
  double robustness = 0;        // correct / trials
  // Accuracy, over the correct trials only. Standard deviations are sample
  // standard deviations (divided by n - 1).
  double translation_mean_mm = 0, translation_std_mm = 0;  // mm
  double rotation_mean = 0, rotation_std = 0;              // 1 - |p.q|
  double rotation_deg_mean = 0, rotation_deg_std = 0;      // degrees
  int timed = 0;                // trials with time_s >= 0
  double time_mean_s = 0;       // mean of time_s over the timed trials (s)
};

ThesisAggregate thesis_aggregate(const std::vector<ThesisTrial>& trials, const ThesisThresholds& thr);

}  // namespace pb
