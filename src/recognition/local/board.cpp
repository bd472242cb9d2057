// Our BOARD local reference frames (Petrelli & Di Stefano 2011), PCL-free, as
// pcl::BOARDLocalReferenceFrameEstimation computes them with holes filled and
// its default tangent radius (0: every neighbour but the keypoint itself is
// a "margin" point), the set-up of PCL's correspondence grouping tutorial
// (tests/pcl_reference/board_pcl.cpp keeps PCL's as the reference):
//   - neighbourhood: every cloud point with squared distance below r^2, in
//     kd-tree order (KdTree3; PCL's is in order of distance, which only
//     changes the rounding of the sums below and which of two equal
//     deviations wins, and sorting it took a third of the warehouse
//     bench's group stage); fewer than 6: no frame;
//   - z: the normal of the least-squares plane through the neighbours,
//     pointing along the mean of their normals;
//   - x: toward the margin point whose normal deviates most from z
//     (projected on the tangent plane), unless the margin has a hole: the
//     margin points' directions around z fall into 24 sectors counted from
//     a start axis; the widest run of empty sectors that is wider than 20%
//     of the circle and whose bordering normals are steep enough (> 0.1)
//     turns x into the hole, between its borders weighted by their normals;
//   - y = z x x.
// Differences from PCL: the plane normal comes from the 3x3 covariance (an
// eigenvector, in double) instead of an SVD of the centred points (the same
// vector up to rounding and sign, and the sign is then set by the normals);
// the start axis is deterministic (PCL draws it with std::rand(), so its
// frames depend on every earlier call in the process) unless
// BoardStartAxis::kCRand asks for PCL's draw.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "core/cpu.h"
#include "recognition/local/internal.h"
#include "recognition/scatter.h"

#if defined(__x86_64__) || defined(__i386__)
#include "core/lanes_avx2.h"
#define PB_BOARD_X86 1
#endif

namespace pb::local {

namespace {

constexpr int kSectors = 24;            // PCL's check_margin_array_size
constexpr float kHoleFraction = 0.2f;   // PCL's hole_size_prob_thresh
constexpr float kSteep = 0.1f;          // PCL's steep_thresh
constexpr float kTwoPi = 2 * static_cast<float>(M_PI);

using Neighbours = std::vector<std::pair<float, int>>;

// The unit direction from `origin` to `p` projected on the plane with unit
// normal `axis` through origin.
Vec3f tangent_direction(const Vec3f& axis, const Vec3f& origin, const Vec3f& p) {
  const Vec3f projected = p - axis.dot(p - origin) * axis;
  return (projected - origin).normalized();
}

// The angle from unit vector a to unit vector b about `axis`, in [0, 2 pi).
float angle_about(const Vec3f& a, const Vec3f& b, const Vec3f& axis) {
  const float angle = std::acos(std::clamp(a.dot(b), -1.0f, 1.0f));
  return a.cross(b).dot(axis) < 0.f ? kTwoPi - angle : angle;
}

// The margin's values for the points idx[0..n): c[k], the cosine of point
// k's normal to z, and angle[k], its direction's angle about z from x0
// (angle_about of tangent_direction from q). One point at a time.
void margin_values_scalar(const PointSet& cloud, const int* idx, size_t n, const Vec3f& q, const Vec3f& z,
                          const Vec3f& x0, float* c, float* angle) {
  for (size_t k = 0; k < n; ++k) {
    const size_t i = static_cast<size_t>(idx[k]);
    c[k] = z.dot(cloud.normals[i]);
    angle[k] = angle_about(x0, tangent_direction(z, q, cloud.points[i]), z);
  }
}

#ifdef PB_BOARD_X86
// The same values eight points at a time: each lane the one-point code's
// float operations in its order (Eigen's dot products and normalized(), a
// division by the root of the squared norm), acosf per lane.
__attribute__((target("avx2"))) void margin_values_avx2(const PointSet& cloud, const int* idx, size_t n,
                                                        const Vec3f& q, const Vec3f& z, const Vec3f& x0, float* c,
                                                        float* angle) {
  const Lanes3 zl = broadcast3(z), ql = broadcast3(q), xl = broadcast3(x0);
  const float* pts = cloud.points.front().data();
  const float* nrm = cloud.normals.front().data();
  const __m256 zero = _mm256_setzero_ps(), lo = _mm256_set1_ps(-1.0f), hi = _mm256_set1_ps(1.0f);
  int lane[8];
  alignas(32) float cs[8], dots[8], acos8[8], negative[8];
  for (size_t k = 0; k < n; k += 8) {
    const size_t count = block_of_eight(idx, k, n, lane);
    const __m256i at = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(lane));
    const Lanes3 p = gather3(pts, at);
    _mm256_store_ps(cs, dot(zl, gather3(nrm, at)));
    // tangent_direction: p - (z . (p - q)) z, minus q, normalized.
    const __m256 s = dot(zl, minus(p, ql));
    const Lanes3 proj{_mm256_sub_ps(p.x, _mm256_mul_ps(s, zl.x)), _mm256_sub_ps(p.y, _mm256_mul_ps(s, zl.y)),
                      _mm256_sub_ps(p.z, _mm256_mul_ps(s, zl.z))};
    const Lanes3 u = minus(proj, ql);
    const __m256 sq = dot(u, u);
    const __m256 root = _mm256_sqrt_ps(sq), positive = _mm256_cmp_ps(sq, zero, _CMP_GT_OQ);
    const Lanes3 t = select(positive,
                            Lanes3{_mm256_div_ps(u.x, root), _mm256_div_ps(u.y, root), _mm256_div_ps(u.z, root)}, u);
    // angle_about: acos of the clamped dot, turned where (x0 x t) . z < 0.
    const __m256 d = dot(xl, t);
    const __m256 below_hi = _mm256_blendv_ps(d, hi, _mm256_cmp_ps(hi, d, _CMP_LT_OQ));
    const __m256 clamped = _mm256_blendv_ps(below_hi, lo, _mm256_cmp_ps(d, lo, _CMP_LT_OQ));
    _mm256_store_ps(dots, clamped);
    _mm256_store_ps(negative, _mm256_cmp_ps(dot(cross(xl, t), zl), zero, _CMP_LT_OQ));
    for (size_t j = 0; j < count; ++j) acos8[j] = std::acos(dots[j]);
    for (size_t j = 0; j < count; ++j) {
      c[k + j] = cs[j];
      angle[k + j] = negative[j] != 0.f ? kTwoPi - acos8[j] : acos8[j];
    }
  }
}
#endif

// The margin's values (margin_values_scalar), eight at a time where the CPU
// has AVX2 (the same bits; test LocalBoard.FramesBitForBitAsFingerprinted).
void margin_values(const PointSet& cloud, const int* idx, size_t n, const Vec3f& q, const Vec3f& z,
                   const Vec3f& x0, float* c, float* angle) {
#ifdef PB_BOARD_X86
  if (cpu_has_avx2()) return margin_values_avx2(cloud, idx, n, q, z, x0, c, angle);
#endif
  margin_values_scalar(cloud, idx, n, q, z, x0, c, angle);
}

// A unit axis orthogonal to z: deterministic, or std::rand()'s as PCL draws
// it (two coordinates uniform in [-1, 1], the third solved for).
Vec3f start_axis(const Vec3f& z, BoardStartAxis how) {
  if (how == BoardStartAxis::kFixed) {
    int least = 0;
    z.cwiseAbs().minCoeff(&least);
    return z.cross(Vec3f::Unit(least)).normalized();
  }
  auto draw = [] { return (static_cast<float>(std::rand()) / static_cast<float>(RAND_MAX)) * 2.0f - 1.0f; };
  Vec3f a = Vec3f::Zero();
  for (int solve : {2, 1, 0}) {  // the first coordinate of z (from z) that is not zero is solved for
    if (std::abs(z[solve]) < 1e-8f) continue;
    const int u = solve == 0 ? 1 : 0, v = solve == 2 ? 1 : 2;
    a[u] = draw();
    a[v] = draw();
    a[solve] = -(z[u] * a[u] + z[v] * a[v]) / z[solve];
    break;
  }
  return a.normalized();
}

// Per sector: whether a margin point falls in it, and the smallest and
// largest angle there with the normal cosine of the point at each.
struct Sectors {
  std::array<bool, kSectors> hit{};
  std::array<float, kSectors> min_angle, max_angle, min_cos, max_cos;
  Sectors() {
    min_angle.fill(std::numeric_limits<float>::max());
    max_angle.fill(-std::numeric_limits<float>::max());
    min_cos.fill(-1.0f);
    max_cos.fill(-1.0f);
  }
  void add(float angle, float normal_cos) {
    const int s = std::min(static_cast<int>(std::floor(angle / (kTwoPi / kSectors))), kSectors - 1);
    hit[static_cast<size_t>(s)] = true;
    if (angle < min_angle[static_cast<size_t>(s)]) {
      min_angle[static_cast<size_t>(s)] = angle;
      min_cos[static_cast<size_t>(s)] = normal_cos;
    }
    if (angle > max_angle[static_cast<size_t>(s)]) {
      max_angle[static_cast<size_t>(s)] = angle;
      max_cos[static_cast<size_t>(s)] = normal_cos;
    }
  }
};

// The angle (from the start axis) of the widest qualifying hole, or false
// when there is none. Runs of empty sectors are scanned from the first
// sector after a hit (a run across sector 0 is one run).
bool widest_hole(const Sectors& s, float min_cos, float* angle) {
  const bool any_empty = std::find(s.hit.begin(), s.hit.end(), false) != s.hit.end();
  const bool any_hit = std::find(s.hit.begin(), s.hit.end(), true) != s.hit.end();
  if (!any_empty || !any_hit) return false;  // no hole, or no margin point to bound one
  const int start = s.hit[kSectors - 1] ? 0 : static_cast<int>(std::find(s.hit.begin(), s.hit.end(), true) - s.hit.begin());
  float best = -std::numeric_limits<float>::max();
  for (int ch = start; ch < kSectors; ++ch) {
    if (s.hit[static_cast<size_t>(ch)]) continue;
    int end = ch + 1;
    while (!s.hit[static_cast<size_t>(end % kSectors)]) ++end;
    const size_t before = static_cast<size_t>((ch - 1 + kSectors) % kSectors), after = static_cast<size_t>(end % kSectors);
    const float nb = 1.0f - (s.max_cos[before] - min_cos) / (1.0f - min_cos);
    const float ne = 1.0f - (s.min_cos[after] - min_cos) / (1.0f - min_cos);
    const float width = after < before ? s.min_angle[after] + kTwoPi - s.max_angle[before]
                                       : s.min_angle[after] - s.max_angle[before];
    const float fraction = width / kTwoPi;
    if (fraction > kHoleFraction && (ne + nb) / 2.0f > kSteep && fraction > best) {
      best = fraction;
      *angle = s.max_angle[before] + width * (((ne - nb) + 1.0f) / 2.0f);
    }
    if (end >= kSectors) break;
    ch = end - 1;
  }
  return best > -std::numeric_limits<float>::max();
}

// The frame of keypoint q (rows x, y, z into row[9]); false when it has none.
// margin, cosines, angles: scratch.
bool board_frame(const Vec3f& q, const PointSet& cloud, const Neighbours& nn, BoardStartAxis how, float* row,
                 std::vector<int>& margin, std::vector<float>& cosines, std::vector<float>& angles) {
  if (nn.size() < 6) return false;
  // z: the plane through the neighbours, oriented by their normals.
  Vec3f centroid = Vec3f::Zero();
  for (const auto& e : nn) centroid += cloud.points[static_cast<size_t>(e.second)];
  centroid /= static_cast<float>(nn.size());
  Scatter3 cov;
  Vec3f normal_sum = Vec3f::Zero();
  for (const auto& e : nn) {
    cov.add((cloud.points[static_cast<size_t>(e.second)] - centroid).cast<double>());
    normal_sum += cloud.normals[static_cast<size_t>(e.second)];
  }
  Vec3f z = Eigen::SelfAdjointEigenSolver<Mat3>(cov.matrix()).eigenvectors().col(0).cast<float>();
  if (z.dot(normal_sum.normalized()) < 0) z = -z;
  // x: the steepest margin point, or the widest hole in the margin.
  const Vec3f x0 = start_axis(z, how);
  float min_cos = std::numeric_limits<float>::max();
  int steepest = -1;
  Sectors sectors;
  margin.clear();
  for (const auto& [d2, i] : nn)
    if (d2 > 0.0f) margin.push_back(i);  // not the keypoint itself (margin distance 0: every other point)
  cosines.resize(margin.size());
  angles.resize(margin.size());
  margin_values(cloud, margin.data(), margin.size(), q, z, x0, cosines.data(), angles.data());
  for (size_t k = 0; k < margin.size(); ++k) {
    if (cosines[k] < min_cos) {
      min_cos = cosines[k];
      steepest = margin[k];
    }
    sectors.add(angles[k], cosines[k]);
  }
  Vec3f x;
  float hole = 0;
  if (steepest >= 0 && widest_hole(sectors, min_cos, &hole)) {
    x = Eigen::AngleAxisf(hole, z) * x0;
  } else {
    if (steepest < 0) {  // every neighbour coincides with q: the steepest of them
      for (const auto& e : nn) {
        const float c = z.dot(cloud.normals[static_cast<size_t>(e.second)]);
        if (c < min_cos) {
          min_cos = c;
          steepest = e.second;
        }
      }
      if (steepest < 0) return false;
    }
    x = tangent_direction(z, q, cloud.points[static_cast<size_t>(steepest)]);
  }
  const Vec3f y = z.cross(x);
  for (int d = 0; d < 3; ++d) {
    row[d] = x[d];
    row[3 + d] = y[d];
    row[6 + d] = z[d];
  }
  return true;
}

}  // namespace

bool usable_frame(const float* row) {
  if (!finite_row(row, kLrfDim)) return false;
  Eigen::Matrix3f R;
  R << row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7], row[8];
  return (R * R.transpose() - Eigen::Matrix3f::Identity()).cwiseAbs().maxCoeff() < 1e-3f;
}

std::vector<float> compute_board_lrf(const PointSet& cloud, const std::vector<int>& keypoints, double radius_mm,
                                     BoardStartAxis start) {
  std::vector<float> out = undescribed_rows(keypoints.size(), kLrfDim);
  if (!can_describe(cloud, keypoints, radius_mm)) return out;
  const CloudNeighbours tree(cloud.points);
  const float r2 = static_cast<float>(radius_mm * radius_mm);
  Neighbours nn;
  std::vector<int> margin;
  std::vector<float> cosines, angles;
  float row[kLrfDim];
  for (size_t k = 0; k < keypoints.size(); ++k) {
    const int p = keypoints[k];
    if (p < 0 || static_cast<size_t>(p) >= cloud.points.size() || !cloud.points[static_cast<size_t>(p)].allFinite())
      continue;
    const Vec3f& q = cloud.points[static_cast<size_t>(p)];
    tree.within(q, r2, nn, false);  // tree order: nothing below needs distance order
    if (board_frame(q, cloud, nn, start, row, margin, cosines, angles) && usable_frame(row))
      std::copy(row, row + kLrfDim, out.begin() + static_cast<long>(k) * kLrfDim);
  }
  return out;
}

}  // namespace pb::local
