// PCL's own implementations of what posebench computes itself: the references
// its FPFH, SHOT, BOARD frames, ESF and Euclidean clusters are tested (and
// benchmarked) against. A test-only library (pb_pcl_reference); the pipeline
// never calls them.
#pragma once

#include <vector>

#include "recognition/cloud.h"

namespace pb::local {

// pcl::FPFHEstimationOMP at the keypoints (33 bins each).
std::vector<float> compute_fpfh_pcl(const PointSet& cloud, const std::vector<int>& keypoints, double radius_mm,
                                    int threads);
// pcl::SHOTEstimationOMP at the keypoints (352 bins each; NaN rows where PCL
// finds the frame invalid).
std::vector<float> compute_shot_pcl(const PointSet& cloud, const std::vector<int>& keypoints, double radius_mm,
                                    int threads);
// pcl::BOARDLocalReferenceFrameEstimation at the keypoints (9 floats each:
// x, y, z axes); the caller seeds std::rand to repeat a result.
std::vector<float> compute_board_lrf_pcl(const PointSet& cloud, const std::vector<int>& keypoints,
                                         double radius_mm);

}  // namespace pb::local

namespace pb::global {

// pcl::EuclideanClusterExtraction, in its order.
std::vector<std::vector<int>> euclidean_clusters_pcl(const std::vector<Vec3f>& points, double tolerance_mm,
                                                     int min_points, int max_points);
// pcl::ESFEstimation (640 bins); seeds rand() from the clock, so neither
// reproducible nor thread-safe.
std::vector<float> pcl_esf(const std::vector<Vec3f>& points);

}  // namespace pb::global
