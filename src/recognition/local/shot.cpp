// Our SHOT (Tombari et al. 2010) at keypoints, PCL-free, as PCL's
// SHOTEstimation defines it (shot_pcl.cpp keeps PCL's as the reference):
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
// rounding level (three-coordinate dot products, sqrt in double, ties in
// distance ordered by index), checked by tests/test_recognition_local_shot.cpp.
// Each row depends on its own neighbourhood only: the same result for any
// thread count.
#ifdef _OPENMP
#include <omp.h>
#endif

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "recognition/local/internal.h"
#include "recognition/scatter.h"

namespace pb::local {

namespace {

constexpr int kCosBins = 10;                // cosine bins per volume (one more slot: cos = 1)
constexpr int kSlots = kCosBins + 1;        // floats per volume
constexpr int kVolumes = kShotDim / kSlots;  // 32
constexpr double kPi = M_PI;
constexpr double kRad45 = kPi / 4, kRad90 = kPi / 2, kRad135 = 3 * kPi / 4, kRad7_8 = 7 * kPi / 8;

using Neighbours = std::vector<std::pair<float, int>>;  // (squared distance, cloud index), by distance

struct Frame {
  Vec3f x, y, z;
};

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

// The volume (0..31) of offset (x, y, z) at `distance`: azimuth sector in
// bits 2-4, upper half in bit 0, outer shell in bit 1 (PCL's numbering).
int volume_of(double x, double y, double z, double distance, double half_radius) {
  const int upper_y = (y > 0) || (y == 0.0 && x < 0);
  const int right_x = (x > 0) || (x == 0.0 && y > 0);
  int v = ((upper_y << 3) + ((right_x ? !upper_y : upper_y) << 2)) << 1;
  if (x * y > 0 || x == 0.0)
    v += std::abs(x) >= std::abs(y) ? 0 : 4;
  else
    v += std::abs(x) > std::abs(y) ? 4 : 0;
  v += z > 0 ? 1 : 0;
  v += distance > half_radius ? 2 : 0;
  return v;
}

// Adds one neighbour's vote (offset d, its normal's cosine bin position
// `bin_pos`) to the histogram h, in PCL's order of additions.
void add_vote(const Vec3f& d, const Frame& f, double distance, double bin_pos, double radius, float* h) {
  const double r14 = radius / 4, r12 = radius / 2, r34 = radius * 3 / 4;
  double x = d.dot(f.x), y = d.dot(f.y), z = d.dot(f.z);
  if (std::abs(y) < 1e-30) y = 0;
  if (std::abs(x) < 1e-30) x = 0;
  if (std::abs(z) < 1e-30) z = 0;
  const int vol = volume_of(x, y, z, distance, r12);
  const int step = static_cast<int>(std::floor(bin_pos + 0.5));
  const int base = vol * kSlots;
  // Cosine: the adjacent bin (circular over the 10 bins) gets the fraction.
  const double frac = bin_pos - step;
  double own = 1 - std::abs(frac);
  if (frac > 0)
    h[base + (step + 1) % kCosBins] += static_cast<float>(frac);
  else
    h[base + (step - 1 + kCosBins) % kCosBins] += -static_cast<float>(frac);
  // Radial: between the shells' middles the inner / outer shell shares.
  if (distance > r12) {
    const double t = (distance - r34) / r12;
    if (distance > r34) {
      own += 1 - t;
    } else {
      own += 1 + t;
      h[(vol - 2) * kSlots + step] -= static_cast<float>(t);
    }
  } else {
    const double t = (distance - r14) / r12;
    if (distance < r14) {
      own += 1 + t;
    } else {
      own += 1 - t;
      h[(vol + 2) * kSlots + step] += static_cast<float>(t);
    }
  }
  // Elevation: between the halves' middles (45 and 135 degrees).
  const double incl = std::acos(std::clamp(z / distance, -1.0, 1.0));
  if (incl > kRad90 || (std::abs(incl - kRad90) < 1e-30 && z <= 0)) {
    const double t = (incl - kRad135) / kRad90;
    if (incl > kRad135) {
      own += 1 - t;
    } else {
      own += 1 + t;
      h[(vol + 1) * kSlots + step] -= static_cast<float>(t);
    }
  } else {
    const double t = (incl - kRad45) / kRad90;
    if (incl < kRad45) {
      own += 1 + t;
    } else {
      own += 1 - t;
      h[(vol - 1) * kSlots + step] += static_cast<float>(t);
    }
  }
  // Azimuth: the neighbouring sector on the side of the offset.
  if (y != 0.0 || x != 0.0) {
    const double az = std::atan2(y, x);
    const int sector = vol >> 2;
    const double t = std::clamp((az - (-kRad7_8 + kRad45 * sector)) / kRad45, -0.5, 0.5);
    if (t > 0) {
      own += 1 - t;
      h[((vol + 4) % kVolumes) * kSlots + step] += static_cast<float>(t);
    } else {
      own += 1 + t;
      h[((vol - 4 + kVolumes) % kVolumes) * kSlots + step] -= static_cast<float>(t);
    }
  }
  h[base + step] += static_cast<float>(own);
}

// The descriptor of keypoint q in frame f into `row` (kShotDim floats);
// false when it has none (fewer than 5 neighbours, an empty histogram).
bool describe(const Vec3f& q, const Frame& f, const PointSet& cloud, const Neighbours& nn, double radius,
              float* row) {
  if (nn.size() < 5) return false;
  std::fill(row, row + kShotDim, 0.0f);
  for (const auto& [d2, i] : nn) {
    const Vec3f& n = cloud.normals[static_cast<size_t>(i)];
    if (!n.allFinite()) continue;
    const double distance = std::sqrt(static_cast<double>(d2));
    if (std::abs(distance) < 1e-15) continue;
    const double c = std::clamp(static_cast<double>(n.dot(f.z)), -1.0, 1.0);
    add_vote(cloud.points[static_cast<size_t>(i)] - q, f, distance, ((1.0 + c) * kCosBins) / 2, radius, row);
  }
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
  std::vector<float> out(keypoints.size() * kShotDim, std::numeric_limits<float>::quiet_NaN());
  if (keypoints.empty() || !cloud.has_normals() || !(radius_mm > 0)) return out;
  const std::vector<Vec3f>& pts = cloud.points;
  const CloudNeighbours tree(cloud.points);
  const float r2 = static_cast<float>(radius_mm * radius_mm);
  const long nk = static_cast<long>(keypoints.size());
#pragma omp parallel num_threads(omp_threads(threads)) if (nk > 16)
  {
    Neighbours nn;
    std::vector<Vec3> off;
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
      if (!framed || !describe(q, f, cloud, nn, radius_mm, row))
        std::fill(row, row + kShotDim, std::numeric_limits<float>::quiet_NaN());
    }
  }
  return out;
}

}  // namespace pb::local
