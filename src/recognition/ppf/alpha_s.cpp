// PPF's alpha_s for a batch of scene pairs where only its bins count
// (ppf/internal.h approx_alpha_s): eight pairs at a time with AVX2, the
// pair's second point taken into the reference frame with Eigen's float
// operations in Eigen's order (no fused multiply-add: the file is built
// with -ffp-contract=off), its angle from series_atan2's double lanes
// instead of atan2f. PCL-free.
#include <immintrin.h>

#include <cmath>

#include "core/cpu.h"
#include "core/lanes_avx2.h"
#include "recognition/ppf/internal.h"

namespace pb::ppf {

namespace {

// The flags' bin, floor((double(a) + pi) / double(step)), of four float lanes.
__attribute__((target("avx2"))) inline __m256d flag_bins(__m128 a, __m256d step) {
  return _mm256_floor_pd(_mm256_div_pd(_mm256_add_pd(_mm256_cvtps_pd(a), _mm256_set1_pd(M_PI)), step));
}

// A coordinate of T * p as Eigen's Affine3f product computes it: ((m0 x +
// m1 y) + m2 z) + m3, T's row (m0, m1, m2, m3).
__attribute__((target("avx2"))) inline __m256 affine_row(const Eigen::Matrix4f& M, int i, const Lanes3& p) {
  const __m256 xy =
      _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(M(i, 0)), p.x), _mm256_mul_ps(_mm256_set1_ps(M(i, 1)), p.y));
  return _mm256_add_ps(_mm256_add_ps(xy, _mm256_mul_ps(_mm256_set1_ps(M(i, 2)), p.z)), _mm256_set1_ps(M(i, 3)));
}

__attribute__((target("avx2"))) void approx_alpha_s_avx2(const Eigen::Affine3f& T, const PointSet& pts,
                                                          const int* idx, size_t n, float step, float* value,
                                                          int* bin) {
  const Eigen::Matrix4f& M = T.matrix();
  const __m256d step_d = _mm256_set1_pd(static_cast<double>(step)), window = _mm256_set1_pd(kAtan2BinWindow);
  const __m256 zero = _mm256_setzero_ps();
  const float* xyz = pts.points.data()->data();
  int lane[8];
  alignas(32) float mid[8];
  alignas(16) int lo_bin[8];
  for (size_t k = 0; k < n; k += 8) {
    const size_t count = block_of_eight(idx, k, n, lane);
    const Lanes3 p = gather3(xyz, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(lane)));
    const __m256 qy = affine_row(M, 1, p), qz = affine_row(M, 2, p);  // q = T * p
    // pcl_alpha: atan2f(-q.z, q.y), its sign kept (both arguments non-zero).
    const __m256 y = _mm256_xor_ps(qz, _mm256_set1_ps(-0.0f)), x = qy;
    const __m256 ok = _mm256_and_ps(_mm256_and_ps(finite_lanes(y), finite_lanes(x)),
                                    _mm256_and_ps(_mm256_cmp_ps(y, zero, _CMP_NEQ_OQ),
                                                  _mm256_cmp_ps(x, zero, _CMP_NEQ_OQ)));
    int sure = _mm256_movemask_ps(ok);
    for (int h = 0; h < 2; ++h) {
      const __m128 yh = h ? _mm256_extractf128_ps(y, 1) : _mm256_castps256_ps128(y);
      const __m128 xh = h ? _mm256_extractf128_ps(x, 1) : _mm256_castps256_ps128(x);
      const __m256d r = series_atan2_lanes(yh, xh);
      _mm_store_ps(mid + 4 * h, _mm256_cvtpd_ps(r));
      const __m256d lo = flag_bins(_mm256_cvtpd_ps(_mm256_sub_pd(r, window)), step_d);
      const __m256d hi = flag_bins(_mm256_cvtpd_ps(_mm256_add_pd(r, window)), step_d);
      // Near +-pi atan2f may give +-float(pi), which pcl_alpha negates: left to it.
      const __m256d inside = _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), r),
                                           _mm256_set1_pd(M_PI - kAtan2BinWindow), _CMP_LT_OQ);
      const __m256d sure_h = _mm256_and_pd(_mm256_cmp_pd(lo, hi, _CMP_EQ_OQ), inside);
      sure &= ~((~_mm256_movemask_pd(sure_h) & 0xf) << (4 * h));
      _mm_store_si128(reinterpret_cast<__m128i*>(lo_bin + 4 * h), _mm256_cvttpd_epi32(lo));
    }
    for (size_t j = 0; j < count; ++j) {
      value[k + j] = mid[j];
      bin[k + j] = (sure >> j) & 1 ? lo_bin[j] : -1;
    }
  }
}

}  // namespace

void approx_alpha_s(const Eigen::Affine3f& T, const PointSet& pts, const int* idx, size_t n, float step,
                    float* value, int* bin) {
  if (cpu_has_avx2()) {
    approx_alpha_s_avx2(T, pts, idx, n, step, value, bin);
    return;
  }
  for (size_t k = 0; k < n; ++k) {
    value[k] = 0;
    bin[k] = -1;
  }
}

}  // namespace pb::ppf
