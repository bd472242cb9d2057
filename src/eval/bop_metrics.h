// The BOP pose errors (MSSD, MSPD, VSD) and their average recall, following
// the BOP toolkit (bop_toolkit_lib/pose_error.py, visibility.py,
// pose_matching.py, score.py, scripts/eval_calc_errors.py and
// eval_calc_scores.py as used by eval_bop19_pose.py; restated in
// ../shared/reference/BOP.md). Poses are T_cam_model in mm; the symmetry set
// comes from eval/symmetry.h.
//
// Differences from the toolkit, all documented where they apply:
// - MSSD/MSPD use the points the caller gives (the mesh vertices), not BOP's
//   resampled models_eval.
// - MSSD returns its true value; the toolkit writes inf when the model origins
//   of the two poses are a diameter or more apart (no effect on the recall
//   whenever the origin lies inside the convex hull of the points).
#pragma once

#include <map>
#include <vector>

#include "core/types.h"

namespace pb {

class DepthRenderer;

// The bop19 settings (eval_bop19_pose.py): np.arange(0.05, 0.51, 0.05) and
// np.arange(5, 51, 5).
std::vector<double> bop19_vsd_taus();          // 0.05, 0.10, ..., 0.50 (fractions of the diameter)
std::vector<double> bop19_vsd_thresholds();    // 0.05, 0.10, ..., 0.50
std::vector<double> bop19_mssd_thresholds();   // 0.05, 0.10, ..., 0.50 (fractions of the diameter)
std::vector<double> bop19_mspd_thresholds();   // 5, 10, ..., 50 (px at an image width of 640)

// ---------------------------------------------------------------- MSSD, MSPD

struct MssdResult {
  double error_mm = 0;  // min over S of max over points x of |T_e x - T_g S x| (mm)
  int symmetry = 0;     // index of the minimizing S (the lowest index on ties)
};

// Maximum Symmetry-aware Surface Distance. `points` in the model frame (mm);
// an empty `symmetries` is treated as {identity}. Throws
// std::invalid_argument for an empty point set.
MssdResult mssd(const Pose& T_est, const Pose& T_gt, const std::vector<Vec3f>& points,
                const std::vector<Pose>& symmetries);

struct MspdResult {
  double error_px = 0;  // min over S of max over x of |proj(T_e x) - proj(T_g S x)| (px)
  int symmetry = 0;     // index of the minimizing S (the lowest index on ties)
};

// Maximum Symmetry-aware Projection Distance through the pinhole K (no
// normalization by the image width here: bop_scores applies 640 / width).
MspdResult mspd(const Pose& T_est, const Pose& T_gt, const Intrinsics& K,
                const std::vector<Vec3f>& points, const std::vector<Pose>& symmetries);

// ----------------------------------------------------------------------- VSD

struct VsdOptions {
  double delta_mm = 15.0;                 // visibility tolerance (bop19: 15 mm; 5 for ITODD)
  std::vector<double> taus = bop19_vsd_taus();  // misalignment tolerances
  bool normalized_by_diameter = true;     // taus are fractions of the diameter (else mm)
  // As eval_calc_errors.py: when the projections of the bounding spheres
  // (radius diameter / 2 about the model origins) do not overlap, every error
  // is 1 without rendering.
  bool sphere_projection_shortcut = true;
};

struct VsdResult {
  std::vector<double> errors;   // one per tau, in [0, 1]; 1 for an empty union
  long visible_gt_px = 0;       // pixels of the GT visibility mask
  long visible_est_px = 0;      // pixels of the estimate's visibility mask
  long intersection_px = 0;     // pixels of both masks
  long union_px = 0;            // pixels of either mask
  bool shortcut = false;        // true when the sphere test decided (nothing rendered)
};

// Visible Surface Discrepancy ("step" cost, "bop19" visibility) from depth
// images already rendered at the estimated and GT poses (mm, 0 = nothing),
// the test image's depth (mm, 0 = no measurement) and its intrinsics; all
// three images must have K's size (std::invalid_argument otherwise).
// Depths are converted to distances from the camera centre as the toolkit
// does. visib_gt = rendered_gt & (d_gt - d_test <= delta | d_test == 0);
// visib_est = rendered_est & (d_est - d_test <= delta | d_test == 0 | visib_gt);
// error(tau) = (#{inter: |d_gt - d_est| / diameter >= tau} + #union - #inter) / #union.
VsdResult vsd_from_renders(const DepthImage& depth_est, const DepthImage& depth_gt,
                           const DepthImage& scene_depth, const Intrinsics& K, double diameter,
                           const VsdOptions& opt = {});

// VSD rendering the model with `renderer` (whose intrinsics are the test
// image's) at both poses.
VsdResult vsd(const Pose& T_est, const Pose& T_gt, const DepthImage& scene_depth, const Mesh& mesh,
              double diameter, DepthRenderer& renderer, const VsdOptions& opt = {});

// The toolkit's misc.overlapping_sphere_projections.
bool sphere_projections_overlap(double radius, const Vec3& center_a, const Vec3& center_b);

// ---------------------------------------------------------- errors of a pose

// What the BOP errors need to know about an object.
struct BopModel {
  const Mesh* mesh = nullptr;     // not owned: rendered for VSD; its vertices are MSSD/MSPD's points
  std::vector<Pose> symmetries;   // symmetry_transformations(models_info entry)
  double diameter = 0;            // mm (models_info "diameter")
};

struct BopErrorOptions {
  VsdOptions vsd;                 // VSD settings
  bool compute_vsd = true;        // VSD needs a renderer and the scene depth
};

struct BopPoseErrors {
  double mssd_mm = 0;             // MSSD (mm)
  double mspd_px = 0;             // MSPD (px, not normalized by the image width)
  std::vector<double> vsd;        // VSD per tau; empty when not computed
  int mssd_symmetry = 0;          // the S of MSSD's minimum
  int mspd_symmetry = 0;          // the S of MSPD's minimum
};

// The three errors of one estimate against one GT. VSD is computed when
// opt.compute_vsd and both scene_depth and renderer are given.
BopPoseErrors bop_pose_errors(const Pose& T_est, const Pose& T_gt, const BopModel& model,
                              const Intrinsics& K, const BopErrorOptions& opt = {},
                              const DepthImage* scene_depth = nullptr,
                              DepthRenderer* renderer = nullptr);

// ------------------------------------------------------ scoring (the recall)

// Errors of one estimate against one GT instance of the same object.
struct BopPairErrors {
  int gt = -1;                    // index into BopImageErrors::gts
  double mssd_mm = 0;             // mm
  double mspd_px = 0;             // px
  std::vector<double> vsd;        // per tau (the same taus for every pair); may be empty
};

struct BopEstimateErrors {
  int obj_id = 0;
  double score = 0;               // confidence: higher is matched first
  double diameter = 0;            // the object's diameter (mm), normalizes MSSD
  std::vector<BopPairErrors> pairs;  // one per GT of obj_id in the image
  int source = -1;                // bop_image_errors: index into BopImageInput::estimates
};

struct BopTarget {
  int obj_id = 0;
  bool valid = true;              // a target to find (BOP's valid GT); invalid GTs are never matched
};

// One image: its GT instances and the errors of its estimates.
struct BopImageErrors {
  int scene_id = 0;
  int im_id = 0;
  int image_width = 640;          // MSPD is scaled by 640 / image_width
  std::vector<BopTarget> gts;
  std::vector<BopEstimateErrors> estimates;
};

struct BopScoreOptions {
  std::vector<double> vsd_thresholds = bop19_vsd_thresholds();    // on the VSD error
  std::vector<double> mssd_thresholds = bop19_mssd_thresholds();  // on MSSD / diameter
  std::vector<double> mspd_thresholds = bop19_mspd_thresholds();  // on MSPD * 640 / width
  // Taus every pair's VSD errors have; -1 = whatever the pairs have (none:
  // VSD is not scored, ar_vsd NaN). Given, targets without any estimate
  // still count for VSD (recall 0), as when VSD was computed but nothing was found.
  int vsd_tau_count = -1;
};

struct BopScores {
  int targets = 0;                // valid GT instances (BOP n_top = -1: every instance is a target)
  int estimates = 0;              // estimates considered (the top `valid count` per image and object)
  std::vector<std::vector<double>> recall_vsd;  // [tau][threshold]
  std::vector<double> recall_mssd;              // [threshold]
  std::vector<double> recall_mspd;              // [threshold]
  double ar_vsd = 0;              // mean of recall_vsd over every (tau, threshold); NaN without VSD errors
  double ar_mssd = 0;             // mean of recall_mssd
  double ar_mspd = 0;             // mean of recall_mspd
  double ar = 0;                  // mean of the three (of the two when VSD is NaN)
};

// BOP 2019 localization scores. Per image and object: estimates sorted by
// decreasing score (stable), only the top k kept with k = the number of valid
// GTs of that object (n_top = -1); then, per threshold, each estimate in turn
// takes the valid, still unmatched GT of its object with the lowest error
// strictly under the threshold. Recall = matches / targets (0 when there are
// no targets). Throws std::invalid_argument for a pair whose gt index is out
// of range or names a GT of another object, or inconsistent VSD sizes.
BopScores bop_scores(const std::vector<BopImageErrors>& images, const BopScoreOptions& opt = {});

// An estimate for bop_image_errors.
struct BopEstimate {
  int obj_id = 0;
  double score = 1.0;
  Pose T_cam_model;
};

// Everything about one test image.
struct BopImageInput {
  int scene_id = 0;
  int im_id = 0;
  Intrinsics K;
  const DepthImage* depth = nullptr;   // the test depth (mm); needed for VSD
  std::vector<int> gt_obj_ids;         // per GT instance
  std::vector<Pose> gt_poses;          // per GT instance, T_cam_model
  std::vector<bool> gt_valid;          // per GT instance; empty = every GT is a target
  std::vector<BopEstimate> estimates;
};

// Computes the errors bop_scores needs for one image: for each object with
// valid GTs, its top-k estimates (as bop_scores keeps) against every GT of
// that object (VSD renders each GT once). Estimates of objects without a
// valid GT are dropped, as in the toolkit. `models` by obj_id; a missing
// model throws std::invalid_argument.
BopImageErrors bop_image_errors(const BopImageInput& in, const std::map<int, BopModel>& models,
                                const BopErrorOptions& opt = {}, DepthRenderer* renderer = nullptr);

}  // namespace pb
