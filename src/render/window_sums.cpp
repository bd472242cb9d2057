// Window sums of the structured-light model, SSE2 and AVX2 (window_sums.h).
#include "render/window_sums.h"

#include "core/cpu.h"
#include "core/round.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define PB_WINDOW_SUMS_X86 1
#endif

namespace pb {

namespace {

#ifdef PB_WINDOW_SUMS_X86

// Four pixels per step, two SSE2 registers of two lanes.
int sums_sse2(const WindowSumRow& a, int u, double* sum, double* count) {
  const __m128d sign = _mm_set1_pd(-0.0), lim = _mm_set1_pd(a.edge), one = _mm_set1_pd(1.0);
  for (; u + 3 + a.r < a.width; u += 4) {
    const double* c = a.d_cmp + a.line + u;
    const __m128d c0 = _mm_loadu_pd(c), c1 = _mm_loadu_pd(c + 2);
    __m128d s0 = _mm_setzero_pd(), s1 = s0, n0 = s0, n1 = s0;
    for (int vv = a.v0; vv <= a.v1; ++vv) {
      const size_t row = static_cast<size_t>(vv) * a.width + u;
      for (int du = -a.r; du <= a.r; ++du) {
        const size_t q = row + du;
        const __m128d m0 = _mm_cmpngt_pd(_mm_andnot_pd(sign, _mm_sub_pd(_mm_loadu_pd(a.d_cmp + q), c0)), lim);
        const __m128d m1 = _mm_cmpngt_pd(_mm_andnot_pd(sign, _mm_sub_pd(_mm_loadu_pd(a.d_cmp + q + 2), c1)), lim);
        s0 = _mm_add_pd(s0, _mm_and_pd(m0, _mm_loadu_pd(a.d_noisy + q)));
        s1 = _mm_add_pd(s1, _mm_and_pd(m1, _mm_loadu_pd(a.d_noisy + q + 2)));
        n0 = _mm_add_pd(n0, _mm_and_pd(m0, one));
        n1 = _mm_add_pd(n1, _mm_and_pd(m1, one));
      }
    }
    _mm_storeu_pd(sum + u, s0);
    _mm_storeu_pd(sum + u + 2, s1);
    _mm_storeu_pd(count + u, n0);
    _mm_storeu_pd(count + u + 2, n1);
  }
  return u;
}

// Eight pixels per step, two AVX registers of four lanes. The same loop as
// sums_sse2 at twice the width, written out again: a function compiled for
// AVX2 must not run on a CPU without it, so one template cannot serve both. _CMP_NGT_UQ is
// SSE2's cmpngt: true when not greater, NaN included.
__attribute__((target("avx2"))) int sums_avx2(const WindowSumRow& a, int u, double* sum, double* count) {
  const __m256d sign = _mm256_set1_pd(-0.0), lim = _mm256_set1_pd(a.edge), one = _mm256_set1_pd(1.0);
  for (; u + 7 + a.r < a.width; u += 8) {
    const double* c = a.d_cmp + a.line + u;
    const __m256d c0 = _mm256_loadu_pd(c), c1 = _mm256_loadu_pd(c + 4);
    __m256d s0 = _mm256_setzero_pd(), s1 = s0, n0 = s0, n1 = s0;
    for (int vv = a.v0; vv <= a.v1; ++vv) {
      const size_t row = static_cast<size_t>(vv) * a.width + u;
      for (int du = -a.r; du <= a.r; ++du) {
        const size_t q = row + du;
        const __m256d m0 = _mm256_cmp_pd(
            _mm256_andnot_pd(sign, _mm256_sub_pd(_mm256_loadu_pd(a.d_cmp + q), c0)), lim, _CMP_NGT_UQ);
        const __m256d m1 = _mm256_cmp_pd(
            _mm256_andnot_pd(sign, _mm256_sub_pd(_mm256_loadu_pd(a.d_cmp + q + 4), c1)), lim, _CMP_NGT_UQ);
        s0 = _mm256_add_pd(s0, _mm256_and_pd(m0, _mm256_loadu_pd(a.d_noisy + q)));
        s1 = _mm256_add_pd(s1, _mm256_and_pd(m1, _mm256_loadu_pd(a.d_noisy + q + 4)));
        n0 = _mm256_add_pd(n0, _mm256_and_pd(m0, one));
        n1 = _mm256_add_pd(n1, _mm256_and_pd(m1, one));
      }
    }
    _mm256_storeu_pd(sum + u, s0);
    _mm256_storeu_pd(sum + u + 4, s1);
    _mm256_storeu_pd(count + u, n0);
    _mm256_storeu_pd(count + u + 4, n1);
  }
  return u;
}

using Kernel = int (*)(const WindowSumRow&, int, double*, double*);

Kernel pick() { return cpu_has_avx2() ? sums_avx2 : sums_sse2; }

#endif

// One pixel's depth from its window sum (the reference for the AVX2 path).
inline float depth_of(double sum, double count, double step, double fb) {
  const double dq = round_half_away(sum / count / step) * step;
  return dq > 0 ? static_cast<float>(fb / dq) : 0.f;
}

void depths_scalar(const double* sum, const double* count, const uint8_t* ok, int u, int end, double step,
                   double fb, float* z) {
  for (; u < end; ++u) z[u] = ok[u] ? depth_of(sum[u], count[u], step, fb) : 0.f;
}

#ifdef PB_WINDOW_SUMS_X86

// Four lanes of depth_of: the same divisions (IEEE, exact in any width),
// truncation by roundpd, and the halves decided as round_half_away does;
// a group with a lane at or beyond 2^52 (or NaN) goes to the scalar path.
// roundpd keeps the sign of a zero that the integer cast drops (-0.3 ->
// -0.0): such a disparity is not positive either way, so its depth is 0.
__attribute__((target("avx2"))) void depths_avx2(const double* sum, const double* count, const uint8_t* ok, int u,
                                                 int end, double step, double fb, float* z) {
  const __m256d vstep = _mm256_set1_pd(step), vfb = _mm256_set1_pd(fb), zero = _mm256_setzero_pd();
  const __m256d half = _mm256_set1_pd(0.5), mhalf = _mm256_set1_pd(-0.5), one = _mm256_set1_pd(1.0);
  const __m256d big = _mm256_set1_pd(4503599627370496.0), sign = _mm256_set1_pd(-0.0);
  for (; u + 4 <= end; u += 4) {
    const __m256d x = _mm256_div_pd(_mm256_div_pd(_mm256_loadu_pd(sum + u), _mm256_loadu_pd(count + u)), vstep);
    if (_mm256_movemask_pd(_mm256_cmp_pd(_mm256_andnot_pd(sign, x), big, _CMP_LT_OQ)) != 0xF) {
      depths_scalar(sum, count, ok, u, u + 4, step, fb, z);
      continue;
    }
    const __m256d t = _mm256_round_pd(x, _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
    const __m256d f = _mm256_sub_pd(x, t);
    __m256d r = _mm256_blendv_pd(t, _mm256_add_pd(t, one), _mm256_cmp_pd(f, half, _CMP_GE_OQ));
    r = _mm256_blendv_pd(r, _mm256_sub_pd(t, one), _mm256_cmp_pd(f, mhalf, _CMP_LE_OQ));
    const __m256d dq = _mm256_mul_pd(r, vstep);
    alignas(16) float out[4];
    _mm_store_ps(out, _mm256_cvtpd_ps(_mm256_div_pd(vfb, dq)));
    const int positive = _mm256_movemask_pd(_mm256_cmp_pd(dq, zero, _CMP_GT_OQ));
    for (int k = 0; k < 4; ++k) z[u + k] = ok[u + k] && ((positive >> k) & 1) ? out[k] : 0.f;
  }
  depths_scalar(sum, count, ok, u, end, step, fb, z);
}

#endif

}  // namespace

void depths_from_sums(const double* sum, const double* count, const uint8_t* ok, int begin, int end, double step,
                      double fb, float* z, WindowSumIsa isa) {
#ifdef PB_WINDOW_SUMS_X86
  const bool avx2 = cpu_has_avx2();
  if (avx2 && isa == WindowSumIsa::best) return depths_avx2(sum, count, ok, begin, end, step, fb, z);
#endif
  depths_scalar(sum, count, ok, begin, end, step, fb, z);
}

int window_sums(const WindowSumRow& row, int u_begin, double* sum, double* count, WindowSumIsa isa) {
#ifdef PB_WINDOW_SUMS_X86
  static const Kernel best = pick();
  const int u = (isa == WindowSumIsa::best ? best : sums_sse2)(row, u_begin, sum, count);
  return sums_sse2(row, u, sum, count);  // the last few that AVX2's eight do not fit
#else
  return u_begin;  // the caller sums every pixel on its own
#endif
}

}  // namespace pb
