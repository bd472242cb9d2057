// Verification: the hypothesis with the most inliers wins (thesis 3.1). An
// inlier is a model point whose nearest scene point is within a threshold.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/types.h"
#include "core/settings_fields.h"
#include "recognition/cloud.h"

namespace pb {

struct VerifySettings {
  double inlier_threshold_mm = 10.0;  // model point -> nearest scene point distance
  // The best hypothesis is accepted only if at least this fraction of its
  // model points are inliers (0 = the thesis: the most inliers wins, as long
  // as it has one); below it the result is "no_hypothesis".
  double min_inlier_fraction = 0.0;
  // Which model cloud the inliers are counted on. "view" (the thesis): the
  // training view the hypothesis came from, so hypotheses from views with
  // more points have an edge. "merged": every view merged in the model frame
  // (voxelized), the same cloud for every hypothesis, so counts compare
  // fairly across views (a flipped pose from a larger view no longer wins).
  std::string inlier_model = "view";

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("inlier_threshold_mm", s.inlier_threshold_mm, fields::length(fields::positive()));
    f("min_inlier_fraction", s.min_inlier_fraction, fields::in_range(0, 1));
    f("inlier_model", s.inlier_model, fields::one_of({"view", "merged"}));
  }
};

// A kd-tree over 3D points (kdtree.h), for nearest neighbour queries.
class PointIndex {
 public:
  explicit PointIndex(const std::vector<Vec3f>& points);
  ~PointIndex();
  // Index of the nearest point with squared distance below max_sq_dist and
  // that distance; -1 if none. `hint`: see KdTree3::nearest.
  int nearest(const Vec3f& q, float* sq_dist = nullptr,
              float max_sq_dist = std::numeric_limits<float>::infinity(), int hint = -1) const;
  std::vector<int> radius(const Vec3f& q, float r) const;
  size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Number of model points (model frame) that, mapped by T_cam_model, have a
// scene point within the threshold.
int count_inliers(const std::vector<Vec3f>& model_points, const Pose& T_cam_model,
                  const PointIndex& scene, double threshold_mm);

}  // namespace pb
