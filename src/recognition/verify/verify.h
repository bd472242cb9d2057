// Verification: ranks the refined hypotheses; the best is the answer.
//   score: inliers     the most inliers wins (thesis 3.1). An inlier is a
//                      model point whose nearest scene point is within a
//                      threshold.
//   score: visibility  what the depth image tells (Vidal et al. 2018; the
//                      clutter and outlier terms of Aldoma et al. 2012's
//                      global hypothesis verification): each model point
//                      that faces the camera is compared with the observed
//                      depth along its pixel's ray; points on the observed
//                      surface support the pose, points in front of it (where
//                      the sensor saw through: free space) contradict it.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/types.h"
#include "core/settings_fields.h"
#include "recognition/cloud.h"

namespace pb {

class KdTree3;

struct VerifySettings {
  double inlier_threshold_mm = 10.0;  // model point -> nearest scene point distance
  // A threshold left relative to the object's diameter (the default 0.05 d)
  // is at most this many preprocess voxels (0 = no cap; a threshold given in
  // mm is taken as given; the sensor floor, scale.min_length_mm, still
  // applies). A voxelized scene has a point within about one voxel of every
  // surface point it saw, so a band several voxels wide also counts points
  // of a wrong pose near the surface: in the warehouse (d 1.8 m, voxel
  // 20 mm) 0.05 d is 4.5 voxels and the LS5 flipped by 180 degrees scored
  // as many inliers as the right pose. The tables' 0.05 d is 0.9-1.5 voxels.
  double inlier_threshold_max_voxels = 2.0;
  // The best hypothesis is accepted only if at least this fraction of its
  // model points are inliers (0 = the thesis: the most inliers wins, as long
  // as it has one); below it the result is "no_hypothesis".
  double min_inlier_fraction = 0.0;
  // Which model cloud the inliers are counted on. "view" (the thesis): the
  // training view the hypothesis came from, so hypotheses from views with
  // more points have an edge. "merged": every view merged in the model frame
  // (voxelized), the same cloud for every hypothesis, so counts compare
  // fairly across views (a flipped pose from a larger view does not win, as
  // it can with "view").
  std::string inlier_model = "view";
  // How hypotheses are ranked: "visibility" (default) or "inliers" (the
  // thesis; its experiments select it). visibility: supported -
  // violation_weight x violating model points (DepthEvidence, tolerance
  // inlier_threshold_mm); ties: inliers, then the method's score. Measured
  // on occluded table scenes with distractors: correct 81 of 210 instead of
  // 66 (configs/experiments/verification.yaml, results/verification).
  std::string score = "visibility";
  double violation_weight = 1.0;  // visibility: what one free-space violation costs, in supported points
  // visibility: a positive score is also scaled by 1 - outline_weight +
  // outline_weight x the share of the pose's outline that stands out against
  // what lies behind it (OutlineEvidence). A pose sunk into a table, a wall
  // or a larger object fits the surface it lies in (its points are on it or
  // behind it), but its outline runs across that surface or behind nearer
  // ones instead of standing out. 0 = off. Measured at 1 against 0, the same
  // trials (configs/experiments/real/recognition.yaml, results/real_recognition):
  // real YCB-Video ppf 12 -> 18 and shot 14 -> 21 of 223 found, every other
  // method within 2; simulated clutter and occluded scenes within 4 per
  // method, none significant.
  double outline_weight = 1.0;
  int outline_gap_px = 3;         // the outline's probe: this many pixels outside the pose's mask
  // Several instances (BOP's inst_count): after the best, the next ranked
  // hypotheses are further instances while they are accepted like the best
  // (an inlier, min_inlier_fraction), score at least instance_min_ratio of
  // the best's verification and lie farther than instance_separation_mm
  // (model origin to model origin) from every instance taken. The ranked
  // hypotheses of a method that forms one per instance (PPF's pose
  // clusters, the local methods' Hough peaks) carry the instances.
  int max_instances = 1;                // at most this many; 0 = every one that passes
  double instance_min_ratio = 0.5;      // a further instance's verification / the best's
  double instance_separation_mm = 40.0; // closer than this to a taken instance: the same one

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("inlier_threshold_mm", s.inlier_threshold_mm, fields::length(fields::positive()));
    f("inlier_threshold_max_voxels", s.inlier_threshold_max_voxels, fields::nonnegative());
    f("min_inlier_fraction", s.min_inlier_fraction, fields::in_range(0, 1));
    f("inlier_model", s.inlier_model, fields::one_of({"view", "merged"}));
    f("score", s.score, fields::one_of({"inliers", "visibility"}));
    f("violation_weight", s.violation_weight, fields::nonnegative());
    f("outline_weight", s.outline_weight, fields::in_range(0, 1));
    f("outline_gap_px", s.outline_gap_px, fields::at_least(1));
    f("max_instances", s.max_instances, fields::nonnegative());
    f("instance_min_ratio", s.instance_min_ratio, fields::in_range(0, 1));
    f("instance_separation_mm", s.instance_separation_mm, fields::length(fields::nonnegative()));
  }
};

// What the depth image says about a pose. Each model point (model frame)
// whose normal faces the camera at T_cam_model and that projects onto a
// pixel with valid depth z_obs (the nearest pixel centre) is one of
//   supported  |z - z_obs| <= tolerance_mm
//   violating  z < z_obs - tolerance_mm: it lies in space the sensor saw
//              through (free space), so the object cannot be there
//   occluded   z > z_obs + tolerance_mm: something is in front of it
// Points facing away, outside the image or on pixels without depth count in
// none. A model without normals counts every point as facing the camera.
struct DepthEvidence {
  int supported = 0, violating = 0, occluded = 0;
  double score(double violation_weight) const { return supported - violation_weight * violating; }
};
DepthEvidence depth_evidence(const PointSet& model, const Pose& T_cam_model, const DepthImage& depth,
                             const Intrinsics& K, double tolerance_mm);

// What the outline of a pose says. The model's camera-facing points are
// drawn into the image as squares of spacing_mm (the cloud's point spacing),
// nearest depth first: the pose's mask. At each pixel of the mask's outline,
// the observed depth gap_px pixels further out (away from the mask) is
//   continuous  within tolerance_mm of the model's depth there: the outline
//               runs across a surface, as for a pose sunk into a table;
//   nearer      nearer by more than tolerance_mm: something in front hides
//               the rim (an occluder, or the surface a sunk pose lies in);
//   standing    farther: the object stands out against what is behind it,
//               as a true pose's visible outline does.
// Probes off the image or without depth count in none.
struct OutlineEvidence {
  int probed = 0;      // outline pixels whose probe has valid depth
  int continuous = 0;  // of those, continuous with the model's depth
  int nearer = 0;      // of those, nearer than the model's depth
  int standing() const { return probed - continuous - nearer; }
  double standing_fraction() const { return probed > 0 ? static_cast<double>(standing()) / probed : 0.0; }
};
OutlineEvidence outline_evidence(const PointSet& model, const Pose& T_cam_model, const DepthImage& depth,
                                 const Intrinsics& K, double spacing_mm, double tolerance_mm, int gap_px);

// verify.score visibility of a pose: depth_evidence's score (tolerance
// inlier_threshold_mm), when positive x (1 - outline_weight + outline_weight
// x the outline's standing fraction; outline_evidence with spacing_mm, the
// cloud's point spacing).
double visibility_score(const PointSet& model, const Pose& T_cam_model, const DepthImage& depth, const Intrinsics& K,
                        const VerifySettings& v, double spacing_mm);

// A kd-tree over 3D points (kdtree.h), for nearest neighbour queries.
class PointIndex {
 public:
  explicit PointIndex(const std::vector<Vec3f>& points);
  ~PointIndex();
  // Index of the nearest point with squared distance below max_sq_dist and
  // that distance; -1 if none. `hint`: see KdTree3::nearest.
  int nearest(const Vec3f& q, float* sq_dist = nullptr,
              float max_sq_dist = std::numeric_limits<float>::infinity(), int hint = -1) const;
  // Some point with squared distance below max_sq_dist, -1 if none: see
  // KdTree3::any_within.
  int any_within(const Vec3f& q, float max_sq_dist, int hint = -1) const;
  std::vector<int> radius(const Vec3f& q, float r) const;
  size_t size() const;
  const KdTree3& tree() const;  // the kd-tree it searches (refinement cuts its crops from it)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Number of model points (model frame) that, mapped by T_cam_model, have a
// scene point within the threshold.
int count_inliers(const std::vector<Vec3f>& model_points, const Pose& T_cam_model,
                  const PointIndex& scene, double threshold_mm);

}  // namespace pb
