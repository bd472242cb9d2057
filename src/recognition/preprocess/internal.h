// Internal helpers of the preprocessing stage, shared by the recognition
// .cpp files (not part of the public contract). PCL-free.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/types.h"
#include "recognition/cloud.h"

namespace pb::detail {

// Seeded RANSAC plane fit (as pcl::SACSegmentation with SACMODEL_PLANE and
// optimized coefficients): `iterations` random triples, the plane with most
// points within `threshold_mm` wins (first found on ties), then a least
// squares refit on its inliers and a final inlier selection. With
// sample_points > 0 (and fewer than the cloud has), the triples are drawn
// from and scored on a seeded random subset of that many points; the
// winner's inliers are then selected among all points. With probability
// below 1 it stops early, as PCL's RandomSampleConsensus: once the
// iterations done make it that likely that a sample of three inliers of the
// best plane so far was drawn. Returns the inlier flags; `plane` (n, d with
// n.p + d = 0) when not null. Fewer than 3 points or no valid sample: all
// false.
std::vector<char> ransac_plane(const std::vector<Vec3f>& points, double threshold_mm, int iterations,
                               uint64_t seed, Eigen::Vector4d* plane = nullptr, int sample_points = 0,
                               double probability = 1.0);

// Points as three arrays of doubles (the float coordinates widened), for
// RANSAC's scoring loop.
struct PlanePoints {
  std::vector<double> x, y, z;
  explicit PlanePoints(const std::vector<Vec3f>& pts);
  size_t size() const { return x.size(); }
};

// How many points lie within `thr` of `plane`: |n . p + d| <= thr, in
// double with n . p summed as Eigen sums an evaluated Vector3d's dot
// product, (n0 p0 + n1 p1) + n2 p2, so the count is that of the scoring
// written with Eigen (test Ransac.CountWithinEqualsEigensTest). Four
// points at a time with AVX2 where the CPU has it (each lane the same
// operations in the same order), one at a time otherwise.
size_t count_within(const PlanePoints& pts, const Eigen::Vector4d& plane, double thr);

// The depth noise of an organized cloud (mm, along the viewing ray): over
// every triple of horizontally adjacent valid pixels of every `row_step`-th
// row, the second difference e = z[i-1] - 2 z[i] + z[i+1] (6 sigma^2 for
// independent noise on a smooth surface; edges are rare and the median
// ignores them), sigma = median |e| / 0.6745 / sqrt(6). 0 with fewer than
// 100 triples. A sensor whose noise is spatially correlated or quantized in
// steps gives less than its noise (second differences mostly 0).
// settings.h's depth_noise_sigma_mm (the sensor floor of relative lengths)
// estimates the same noise differently (the RMS of the second differences
// below 2% of the depth, every row of the depth image); the two are kept
// apart because each set of results was measured with its own, and either
// one replacing the other would move them.
double depth_noise_sigma(const OrganizedCloud& cloud, int row_step = 4);
// Whether depth_noise_sigma(cloud, row_step) * factor > threshold, from a
// count of the second differences (no median unless it is needed).
bool depth_noise_exceeds(const OrganizedCloud& cloud, double factor, double threshold, int row_step = 4);


// Mixed ("flying", "veil") pixels of an organized cloud: flags a valid pixel
// when the 3D step to one of its valid 8-neighbours lies within `angle_deg`
// of the pixel's viewing ray (a surface seen that edge-on returns almost no
// light, so such a step is a depth edge, not a surface). Flags the pixels
// between the two sides of a depth edge and the edge's last pixel on each
// side; a surface facing the camera keeps every pixel unless the noise
// between two neighbours exceeds their spacing / tan(angle_deg).
std::vector<char> veil_pixels(const OrganizedCloud& cloud, double angle_deg);

// The valid pixels (every coordinate finite) with z within [min_z, max_z]
// (mm), except those flagged in `drop` (empty: none; else one flag per
// pixel), in pixel order with their pixel indices. `best` takes eight
// pixels at a time with AVX2 where the CPU has it; `scalar` one at a time:
// the same points (test RangeCut.VectorAndScalarKeepTheSamePixels). box
// (when not null, 6 floats): the kept points' box, lo x y z then hi x y z
// (lo > hi when none is kept), for the voxel grid (VoxelGridOptions::box).
enum class RangeCutIsa { best, scalar };
PointSet range_cut(const OrganizedCloud& cloud, double min_z, double max_z, const std::vector<char>& drop = {},
                   RangeCutIsa isa = RangeCutIsa::best, float* box = nullptr);

// The pixels of every n-th column of every n-th row (n >= 1), and their
// `drop` flags thinned alike (when not empty): an organized cloud of
// ceil(width / n) x ceil(height / n) pixels.
OrganizedCloud every_nth_pixel(const OrganizedCloud& cloud, int n, std::vector<char>& drop);

// Keeps the points whose flag is set (all per-point arrays).
PointSet select(const PointSet& in, const std::vector<char>& keep);

}  // namespace pb::detail
