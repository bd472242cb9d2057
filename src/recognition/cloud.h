// PCL-free point sets passed between recognition stages. Stage
// implementations convert to PCL types inside their .cpp files.
#pragma once

#include <string>
#include <vector>

#include "core/stage_times.h"  // StageTimes
#include "core/types.h"

namespace pb {

// An unorganized cloud with normals (mm). `pixel` keeps the link to the
// organized source image (index v * width + u, or -1), so later stages can
// exploit the organized structure.
struct PointSet {
  std::vector<Vec3f> points;
  std::vector<Vec3f> normals;    // unit, oriented toward the viewpoint; may be empty
  std::vector<float> curvature;  // surface variation; may be empty
  std::vector<int> pixel;        // may be empty (a preprocessed scene keeps none: preprocess.h)
  int source_width = 0, source_height = 0;

  size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_normals() const { return normals.size() == points.size() && !points.empty(); }
};

// The points `indices` name, in that order, with every per-point field the
// cloud has (normals, curvature, pixel).
PointSet subset(const PointSet& cloud, const std::vector<int>& indices);

// A pose hypothesis for the object in the scene.
struct Hypothesis {
  Pose T_cam_model;      // model -> scene camera
  int view = -1;         // training view it came from (-1: none)
  double score = 0;      // method-specific (votes, 1/histogram distance, ...), higher is better
  int inliers = 0;       // set by verification
  double verification = 0;  // what verification ranked it by (verify.score: inliers or visibility)
  bool refined = false;
};


}  // namespace pb
