// Preprocessing (thesis 3.1.1 and 3.2.1): range cut, voxel grid,
// dominant plane removal, normals. The voxel grid and the RANSAC plane fit
// are implemented here (same cells and semantics as pcl::VoxelGrid and
// pcl::SACSegmentation) so that each output point keeps its source pixel and
// every random choice draws from pb::Rng; normals go through PCL
// (preprocess_normals.cpp).
#include "recognition/preprocess/preprocess.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include <Eigen/Eigenvalues>

#include "core/cpu.h"
#include "core/random.h"
#include "recognition/preprocess/internal.h"
#include "recognition/preprocess/voxel_grid.h"
#include "recognition/scatter.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define PB_PREPROCESS_X86 1
#endif

namespace pb {

void PreprocessSettings::validate(const YamlNode& node) const {
  if (max_range_mm <= min_range_mm)
    node["max_range_mm"].fail("must be greater than min_range_mm (" + std::to_string(min_range_mm) + ")");
}

double PreprocessSettings::normal_support_leaf_mm() const {
  if (!normal_coarse_support || normal_max_points <= 0 || !(voxel_mm > 0)) return 0;
  // About normal_max_points cells of this leaf cover the ball's flat disc.
  const double leaf = normal_radius_mm * std::sqrt(M_PI / normal_max_points);
  return leaf >= 1.5 * voxel_mm ? leaf : 0;
}

namespace detail {

PointSet select(const PointSet& in, const std::vector<char>& keep) {
  PointSet out;
  out.source_width = in.source_width;
  out.source_height = in.source_height;
  const bool n = in.normals.size() == in.points.size(), c = in.curvature.size() == in.points.size(),
             px = in.pixel.size() == in.points.size();
  for (size_t i = 0; i < in.points.size(); ++i) {
    if (!keep[i]) continue;
    out.points.push_back(in.points[i]);
    if (n) out.normals.push_back(in.normals[i]);
    if (c) out.curvature.push_back(in.curvature[i]);
    if (px) out.pixel.push_back(in.pixel[i]);
  }
  return out;
}


namespace {

// Least squares plane through points (PCA): the normal is the eigenvector of
// the smallest eigenvalue of the covariance.
bool fit_plane(const std::vector<Vec3f>& pts, const std::vector<char>& use, Eigen::Vector4d& plane) {
  Vec3 mean = Vec3::Zero();
  size_t cnt = 0;
  for (size_t i = 0; i < pts.size(); ++i)
    if (use[i]) {
      mean += pts[i].cast<double>();
      ++cnt;
    }
  if (cnt < 3) return false;
  mean /= static_cast<double>(cnt);
  Scatter3 cov;
  for (size_t i = 0; i < pts.size(); ++i)
    if (use[i]) cov.add(pts[i].cast<double>() - mean);
  Eigen::SelfAdjointEigenSolver<Mat3> es(cov.matrix());
  if (es.info() != Eigen::Success) return false;
  const Vec3 nrm = es.eigenvectors().col(0).normalized();
  if (!nrm.allFinite()) return false;
  plane << nrm, -nrm.dot(mean);
  return true;
}

// |n . p + d| <= thr for the plane (n, d), n . p summed (n0 p0 + n1 p1) +
// n2 p2 in double: how Eigen sums an evaluated Vector3d's dot product, the
// form this test had (test Ransac.CountWithinEqualsEigensTest).
inline bool on_plane(const Eigen::Vector4d& plane, double x, double y, double z, double thr) {
  return std::abs(((plane[0] * x + plane[1] * y) + plane[2] * z) + plane[3]) <= thr;
}

// The points within thr of the plane, flagged.
size_t within(const std::vector<Vec3f>& pts, const Eigen::Vector4d& plane, double thr, std::vector<char>* flags) {
  size_t cnt = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    const bool in = on_plane(plane, pts[i].x(), pts[i].y(), pts[i].z(), thr);
    cnt += in;
    (*flags)[i] = in;
  }
  return cnt;
}

}  // namespace

PlanePoints::PlanePoints(const std::vector<Vec3f>& pts) {
  x.reserve(pts.size());
  y.reserve(pts.size());
  z.reserve(pts.size());
  for (const Vec3f& p : pts) {
    x.push_back(p.x());
    y.push_back(p.y());
    z.push_back(p.z());
  }
}

namespace {

#ifdef PB_PREPROCESS_X86
// Four points per step: each lane on_plane's operations in its order (no
// fused multiply-add: the target is AVX2 alone), a lane's count raised by
// subtracting its all-ones mask. Returns the first point not done.
__attribute__((target("avx2"))) size_t count_within_avx2(const PlanePoints& pts, const Eigen::Vector4d& plane,
                                                         double thr, size_t* count) {
  const __m256d n0 = _mm256_set1_pd(plane[0]), n1 = _mm256_set1_pd(plane[1]), n2 = _mm256_set1_pd(plane[2]),
                d = _mm256_set1_pd(plane[3]), t = _mm256_set1_pd(thr), sign = _mm256_set1_pd(-0.0);
  __m256i cnt = _mm256_setzero_si256();
  size_t i = 0;
  for (; i + 4 <= pts.size(); i += 4) {
    const __m256d xy = _mm256_add_pd(_mm256_mul_pd(n0, _mm256_loadu_pd(&pts.x[i])),
                                     _mm256_mul_pd(n1, _mm256_loadu_pd(&pts.y[i])));
    const __m256d e = _mm256_add_pd(_mm256_add_pd(xy, _mm256_mul_pd(n2, _mm256_loadu_pd(&pts.z[i]))), d);
    cnt = _mm256_sub_epi64(cnt, _mm256_castpd_si256(_mm256_cmp_pd(_mm256_andnot_pd(sign, e), t, _CMP_LE_OQ)));
  }
  alignas(32) uint64_t lanes[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), cnt);
  *count = static_cast<size_t>(lanes[0] + lanes[1] + lanes[2] + lanes[3]);
  return i;
}

#endif

}  // namespace

size_t count_within(const PlanePoints& pts, const Eigen::Vector4d& plane, double thr) {
  size_t cnt = 0, i = 0;
#ifdef PB_PREPROCESS_X86
  const bool avx2 = cpu_has_avx2();
  if (avx2) i = count_within_avx2(pts, plane, thr, &cnt);
#endif
  for (; i < pts.size(); ++i) cnt += on_plane(plane, pts.x[i], pts.y[i], pts.z[i], thr) ? 1 : 0;
  return cnt;
}

std::vector<char> ransac_plane(const std::vector<Vec3f>& all, double thr, int iterations, uint64_t seed,
                               Eigen::Vector4d* plane_out, int sample_points, double probability) {
  const size_t n = all.size();
  std::vector<char> flags(n, 0);
  if (n < 3) return flags;
  Rng rng(seed);
  // The points the candidates are drawn from and scored on.
  std::vector<Vec3f> subset;
  if (sample_points > 0 && static_cast<size_t>(sample_points) < n) {
    subset.reserve(static_cast<size_t>(sample_points));
    const int max_i = static_cast<int>(n) - 1;
    for (int k = 0; k < sample_points; ++k) subset.push_back(all[static_cast<size_t>(rng.uniform_int(0, max_i))]);
  }
  const std::vector<Vec3f>& pts = subset.empty() ? all : subset;
  const PlanePoints scored(pts);
  Eigen::Vector4d best = Eigen::Vector4d::Zero();
  size_t best_count = 0;
  const int max_n = static_cast<int>(pts.size()) - 1;
  for (int it = 0; it < iterations; ++it) {
    const int a = rng.uniform_int(0, max_n), b = rng.uniform_int(0, max_n), c = rng.uniform_int(0, max_n);
    if (a == b || b == c || a == c) continue;  // a degenerate sample costs its iteration, as in PCL
    const Vec3 pa = pts[a].cast<double>(), pb_ = pts[b].cast<double>(), pc = pts[c].cast<double>();
    Vec3 nrm = (pb_ - pa).cross(pc - pa);
    const double l = nrm.norm();
    if (!(l > 1e-9)) continue;  // collinear sample
    nrm /= l;
    Eigen::Vector4d plane;
    plane << nrm, -nrm.dot(pa);
    const size_t cnt = count_within(scored, plane, thr);
    if (cnt > best_count) {
      best_count = cnt;
      best = plane;
      // Adaptive stop (as PCL's RandomSampleConsensus): enough iterations
      // that a sample of three inliers of the best plane so far was drawn
      // with `probability`.
      if (probability < 1) {
        const double w = static_cast<double>(cnt) / static_cast<double>(pts.size());
        const double p_good = w * w * w;
        if (p_good >= 1) break;
        const double needed = std::log(1 - probability) / std::log(1 - p_good);
        iterations = static_cast<int>(std::min<double>(iterations, std::ceil(needed)));
      }
    }
  }
  if (best_count < 3) return flags;
  const size_t support = within(all, best, thr, &flags);
  Eigen::Vector4d refined;
  if (fit_plane(all, flags, refined)) {
    // Keep the refit only if it does not lose support (PCL keeps the refit
    // unconditionally; a refit tilted by a large object can lose the plane).
    std::vector<char> f2(n, 0);
    if (within(all, refined, thr, &f2) >= support) {
      best = refined;
      flags.swap(f2);
    }
  }
  if (plane_out) *plane_out = best;
  return flags;
}

namespace {

// The second differences |z[i-1] - 2 z[i] + z[i+1]| of depth_noise_sigma,
// each passed to visit; false (none visited) if the cloud is not
// organized.
template <class Visit>
bool visit_second_differences(const OrganizedCloud& cloud, int row_step, Visit visit) {
  const int w = cloud.width, h = cloud.height;
  if (w < 3 || h < 1 || cloud.points.size() != static_cast<size_t>(w) * static_cast<size_t>(h)) return false;
  for (int y = 0; y < h; y += std::max(1, row_step)) {
    const Vec3f* row = cloud.points.data() + static_cast<size_t>(y) * static_cast<size_t>(w);
    for (int x = 1; x + 1 < w; ++x) {
      const float a = row[x - 1].z(), b = row[x].z(), c = row[x + 1].z();
      if (std::isfinite(a) && std::isfinite(b) && std::isfinite(c)) visit(std::abs(a - 2 * b + c));
    }
  }
  return true;
}

double sigma_of_median(float e) { return static_cast<double>(e) / 0.6745 / std::sqrt(6.0); }

}  // namespace

double depth_noise_sigma(const OrganizedCloud& cloud, int row_step) {
  std::vector<float> e;
  visit_second_differences(cloud, row_step, [&e](float v) { e.push_back(v); });
  if (e.size() < 100) return 0;
  const auto mid = e.begin() + static_cast<std::ptrdiff_t>(e.size() / 2);
  std::nth_element(e.begin(), mid, e.end());
  return sigma_of_median(*mid);
}

bool depth_noise_exceeds(const OrganizedCloud& cloud, double factor, double threshold, int row_step) {
  // sigma_of_median(e) * factor > threshold is non-decreasing in e, so it
  // holds for the median (the element at n / 2 in ascending order) exactly
  // when at most n / 2 of the values fail it.
  size_t n = 0, fail = 0;
  visit_second_differences(cloud, row_step, [&](float v) {
    ++n;
    fail += sigma_of_median(v) * factor > threshold ? 0 : 1;
  });
  return n >= 100 && fail <= n / 2;
}

std::vector<char> veil_pixels(const OrganizedCloud& cloud, double angle_deg) {
  const int W = cloud.width, H = cloud.height;
  std::vector<char> veil(cloud.points.size(), 0);
  if (!(angle_deg > 0) || W < 2 || H < 2) return veil;
  // |d . r| > cos(angle) |d|, squared: (d . r)^2 > cos^2 |d|^2 (r unit).
  const double c2 = std::pow(std::cos(angle_deg * M_PI / 180.0), 2);
  auto valid = [](const Vec3f& p) { return std::isfinite(p.z()) && p.z() > 0; };
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      const size_t i = static_cast<size_t>(v) * W + u;
      const Vec3f& p = cloud.points[i];
      if (!valid(p)) continue;
      const Eigen::Vector3d r = p.cast<double>().normalized();
      // Each unordered pair once (the right half of the 8-neighbourhood),
      // flagging both ends.
      for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 1}, std::pair{0, 1}, std::pair{1, 1}}) {
        const int uu = u + du, vv = v + dv;
        if (uu < 0 || uu >= W || vv >= H) continue;
        const size_t j = static_cast<size_t>(vv) * W + uu;
        const Vec3f& q = cloud.points[j];
        if (!valid(q)) continue;
        const Eigen::Vector3d d = (q - p).cast<double>();
        const double along = d.dot(r);
        if (along * along > c2 * d.squaredNorm()) veil[i] = veil[j] = 1;
      }
    }
  return veil;
}

}  // namespace detail

namespace {

// The dominant planes removed from `ps`, one after the other (max_planes,
// min_plane_fraction of the points it had first), each RANSAC'd with its
// own seed and widened by the image's depth noise (plane_noise_factor).
// The median |cos| of the widening is taken over every plane point, or with
// `median_points` > 0 over about that many of them, evenly spaced in point
// order (a table frame's raw points: a quarter million).
void remove_planes(PointSet& ps, const OrganizedCloud& cloud, const PreprocessSettings& s, uint64_t seed,
                   size_t median_points = 0) {
  const double min_count = s.min_plane_fraction * static_cast<double>(ps.size());
  // The noise's widening applies when depth_noise_sigma * plane_noise_factor
  // exceeds the threshold; the median itself is found only then.
  const bool widen = s.plane_noise_factor > 0 &&
                     detail::depth_noise_exceeds(cloud, s.plane_noise_factor, s.plane_threshold_mm);
  const double depth_sigma = widen ? detail::depth_noise_sigma(cloud) : 0.0;
  for (int k = 0; k < s.max_planes && ps.size() >= 3; ++k) {
    Eigen::Vector4d plane;
    std::vector<char> on_plane = detail::ransac_plane(ps.points, s.plane_threshold_mm, s.plane_iterations,
                                                      k == 0 ? seed : derive_seed(seed, {static_cast<uint64_t>(k)}),
                                                      &plane, s.plane_sample_points, s.plane_probability);
    if (widen) {
      // Depth noise along the rays, seen across the plane: x the median
      // |cos| between the plane's normal and the rays to its points.
      std::vector<double> cosines;
      size_t stride = 1;
      if (median_points > 0) {
        const size_t on = static_cast<size_t>(std::count(on_plane.begin(), on_plane.end(), 1));
        stride = std::max<size_t>(1, on / median_points);
      }
      for (size_t i = 0, seen = 0; i < ps.size(); ++i)
        if (on_plane[i] && seen++ % stride == 0)
          cosines.push_back(std::abs(plane.head<3>().dot(ps.points[i].cast<double>().normalized())));
      if (!cosines.empty()) {
        const auto mid = cosines.begin() + static_cast<std::ptrdiff_t>(cosines.size() / 2);
        std::nth_element(cosines.begin(), mid, cosines.end());
        const double wide = s.plane_noise_factor * depth_sigma * *mid;
        if (wide > s.plane_threshold_mm)
          for (size_t i = 0; i < ps.size(); ++i)
            on_plane[i] = std::abs(plane.head<3>().dot(ps.points[i].cast<double>()) + plane[3]) <= wide;
      }
    }
    const size_t cnt = static_cast<size_t>(std::count(on_plane.begin(), on_plane.end(), 1));
    if (cnt == 0 || static_cast<double>(cnt) < min_count) break;
    std::vector<char> keep(on_plane.size());
    for (size_t i = 0; i < keep.size(); ++i) keep[i] = !on_plane[i];
    ps = detail::select(ps, keep);
  }
}

}  // namespace

PointSet preprocess_scene(const OrganizedCloud& cloud, const PreprocessSettings& s, uint64_t seed) {
  float box[6];  // the range cut's points' box, which the grid needs first
  std::vector<char> veil = s.veil_angle_deg > 0 ? detail::veil_pixels(cloud, s.veil_angle_deg) : std::vector<char>{};
  OrganizedCloud thinned;  // pixel_stride > 1: the pixels the cut reads (the veil found on all of them)
  if (s.pixel_stride > 1) thinned = detail::every_nth_pixel(cloud, s.pixel_stride, veil);
  PointSet ps = detail::range_cut(s.pixel_stride > 1 ? thinned : cloud, s.min_range_mm, s.max_range_mm, veil,
                                  detail::RangeCutIsa::best, box);
  ps.pixel.clear();  // no cell's nearest pixel wanted (preprocess.h)
  ps.source_width = cloud.width;
  ps.source_height = cloud.height;
  VoxelGridOptions grid{s.voxel_mm};
  grid.box = box;
  // Before the grid: the range-cut points, the widening's median over
  // about plane_sample_points of the plane's (all with 0). The box is then
  // the grid's to find.
  if (s.remove_plane && s.planes_before_grid) {
    remove_planes(ps, cloud, s, seed, static_cast<size_t>(s.plane_sample_points));
    grid.box = nullptr;
  }
  ps = voxel_downsample(ps, grid);
  if (s.remove_plane && !s.planes_before_grid) remove_planes(ps, cloud, s, seed);
  radius_normals(ps, s.normal_radius_mm, s.normal_max_points, s.normal_support_leaf_mm());
  return ps;
}

PointSet preprocess_view(const OrganizedCloud& cloud, const PreprocessSettings& s, uint64_t /*seed*/) {
  // The model is alone in its view, rendered at the distance the view
  // settings chose: no range cut, no plane.
  float box[6];
  PointSet ps =
      detail::range_cut(cloud, 0.0, std::numeric_limits<double>::infinity(), {}, detail::RangeCutIsa::best, box);
  VoxelGridOptions grid{s.voxel_mm};
  grid.box = box;
  ps = voxel_downsample(ps, grid);
  radius_normals(ps, s.normal_radius_mm, s.normal_max_points, s.normal_support_leaf_mm());
  return ps;
}

}  // namespace pb
