// Our SHOT (Tombari et al. 2010) at keypoints, PCL-free, as PCL's
// SHOTEstimation defines it (tests/pcl_reference/shot_pcl.cpp keeps PCL's as the reference):
//   - one neighbourhood per keypoint: every cloud point with squared
//     distance below r^2 (FLANN's strict radius) in order of distance, found
//     once on the project's kd-tree and used for both the frame and the
//     histogram (PCL searches twice, the frame radius being the descriptor's);
//   - the local reference frame: the eigenvectors of the covariance of the
//     offsets to the keypoint weighted by r - distance (points equal to the
//     keypoint left out; fewer than 5 others: no frame), x the largest and z
//     the smallest, each pointing where most offsets point (a tie: the five
//     offsets around the median distance decide), y = z x x;
//   - the histogram: 32 volumes (8 azimuth sectors, 2 elevations, 2 radial
//     shells) of 11 bins of the cosine between the neighbour's normal and z,
//     every neighbour's vote spread linearly to the adjacent cosine bin,
//     shell, elevation and azimuth sector; scaled to unit L2 norm.
// PCL's arithmetic is followed step by step (double where PCL uses double,
// the same order of additions per bin); remaining differences are at
// rounding level (three-coordinate dot products, sqrt in double, acos and
// atan2 from core/trig.h's series, ties in distance ordered by index),
// checked by tests/test_recognition_local_shot.cpp.
// The histogram's votes are shot_votes.cpp's (four at a time with AVX2, the
// same bits). Each row depends on its own neighbourhood only: the same
// result for any thread count.
#ifdef _OPENMP
#include <omp.h>
#endif

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "recognition/local/internal.h"
#include "recognition/local/shot_votes.h"
#include "recognition/scatter.h"

namespace pb::local {

namespace {

using Neighbours = std::vector<std::pair<float, int>>;  // (squared distance, cloud index), by distance

using Frame = ShotFrame;

// `count` offsets pointing along `axis` (dot >= 0), as a majority sign: the
// axis is flipped when fewer than half point along it; on a tie the five
// offsets around the median distance vote (dot > 0).
Vec3 disambiguate(Vec3 axis, const std::vector<Vec3>& off) {
  const int n = static_cast<int>(off.size());
  int plus = 0;
  for (const Vec3& o : off) plus += o.dot(axis) >= 0;
  int balance = 2 * plus - n;
  if (balance == 0) {
    const int mid = n / 2;
    for (int i = -2; i <= 2; ++i) balance += off[static_cast<size_t>(mid - i)].dot(axis) > 0;
    if (balance < 3) axis = -axis;
  } else if (balance < 0) {
    axis = -axis;
  }
  return axis;
}

// The SHOT local reference frame of keypoint q (see the file comment); false
// when it has no frame. `off`: scratch for the offsets.
bool reference_frame(const Vec3f& q, const std::vector<Vec3f>& pts, const Neighbours& nn, double radius, Frame* f,
                     std::vector<Vec3>& off) {
  off.clear();
  Scatter3 scatter;
  double sum = 0;
  for (const auto& [d2, i] : nn) {
    const Vec3f& p = pts[static_cast<size_t>(i)];
    if (p == q) continue;
    const Vec3 v = (p - q).cast<double>();
    const double w = radius - std::sqrt(static_cast<double>(d2));
    scatter.add_weighted(w, v);
    sum += w;
    off.push_back(v);
  }
  if (off.size() < 5) return false;
  const Mat3 cov = scatter.matrix() / sum;
  const Eigen::SelfAdjointEigenSolver<Mat3> es(cov);
  if (!es.eigenvalues().allFinite()) return false;
  const Vec3 x = disambiguate(es.eigenvectors().col(2), off);
  const Vec3 z = disambiguate(es.eigenvectors().col(0), off);
  f->x = x.cast<float>();
  f->z = z.cast<float>();
  f->y = f->z.cross(f->x);
  return true;
}

// The descriptor of keypoint q in frame f into `row` (kShotDim floats);
// false when it has none (fewer than 5 neighbours, an empty histogram).
bool describe(const Vec3f& q, const Frame& f, const PointSet& cloud, const Neighbours& nn, double radius,
              float* row, ShotVotes& votes) {
  if (nn.size() < 5) return false;
  votes.clear();
  for (const auto& [d2, i] : nn) {
    const Vec3f& n = cloud.normals[static_cast<size_t>(i)];
    if (!n.allFinite()) continue;
    const double distance = std::sqrt(static_cast<double>(d2));
    if (std::abs(distance) < 1e-15) continue;
    votes.push(cloud.points[static_cast<size_t>(i)] - q, n.dot(f.z), distance);
  }
  std::array<float, kShotDim + 1> h{};  // and add_shot_votes' spare slot
  add_shot_votes(votes, f, radius, h.data());
  std::copy(h.begin(), h.begin() + kShotDim, row);
  double norm = 0;
  for (int j = 0; j < kShotDim; ++j) norm += row[j] * row[j];
  if (!(norm > 0)) return false;
  const float s = static_cast<float>(std::sqrt(norm));
  for (int j = 0; j < kShotDim; ++j) row[j] /= s;
  return true;
}

}  // namespace

std::vector<float> compute_shot(const PointSet& cloud, const std::vector<int>& keypoints, double radius_mm,
                                int threads, int max_support) {
  std::vector<float> out = undescribed_rows(keypoints.size(), kShotDim);
  if (!can_describe(cloud, keypoints, radius_mm)) return out;
  const std::vector<Vec3f>& pts = cloud.points;
  const CloudNeighbours tree(cloud.points);
  const float r2 = static_cast<float>(radius_mm * radius_mm);
  const long nk = static_cast<long>(keypoints.size());
#pragma omp parallel num_threads(omp_threads(threads)) if (nk > 16)
  {
    Neighbours nn;
    std::vector<Vec3> off;
    ShotVotes votes;
#pragma omp for schedule(dynamic, 16)
    for (long k = 0; k < nk; ++k) {
      const int p = keypoints[static_cast<size_t>(k)];
      if (p < 0 || static_cast<size_t>(p) >= pts.size() || !pts[static_cast<size_t>(p)].allFinite()) continue;
      const Vec3f& q = pts[static_cast<size_t>(p)];
      tree.within(q, r2, nn);
      Frame f;
      float* row = out.data() + static_cast<size_t>(k) * kShotDim;
      // The frame from every neighbour (thinned, it turns: on the tests'
      // surface 128 of ~175 points left 9 of 46 rows nearer another
      // keypoint's full row than their own), the histogram from an even
      // sample in order of distance.
      const bool framed = reference_frame(q, pts, nn, radius_mm, &f, off);
      keep_evenly(nn, max_support);
      if (!framed || !describe(q, f, cloud, nn, radius_mm, row, votes))
        std::fill(row, row + kShotDim, std::numeric_limits<float>::quiet_NaN());
    }
  }
  return out;
}

}  // namespace pb::local
