// core/trig.h's atan_unit, series_acos and series_atan2_double for four
// double lanes (AVX2), each lane the scalar function's operations in its
// order: the same bits. Include only in files built with -ffp-contract=off.
#pragma once

#include <immintrin.h>

#include "core/trig.h"

namespace pb {

// atan_unit per lane (a NaN lane stays NaN).
__attribute__((target("avx2"))) inline __m256d atan_unit4(__m256d t) {
  const __m256d q = _mm256_round_pd(_mm256_add_pd(_mm256_mul_pd(t, _mm256_set1_pd(4.0)), _mm256_set1_pd(0.5)),
                                    _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __m256d c = _mm256_mul_pd(q, _mm256_set1_pd(0.25));
  const __m256d u = _mm256_div_pd(_mm256_sub_pd(t, c), _mm256_add_pd(_mm256_set1_pd(1.0), _mm256_mul_pd(t, c)));
  const __m256d w = _mm256_mul_pd(u, u);
  __m256d s = _mm256_set1_pd(kAtanSeries[0]);
  for (int k = 1; k < 9; ++k) s = _mm256_add_pd(_mm256_mul_pd(s, w), _mm256_set1_pd(kAtanSeries[k]));
  // atan of the quarter: kAtanQuarters[q] (0 where q is 0 or NaN).
  __m256d base = _mm256_setzero_pd();
  for (int k = 1; k <= 4; ++k)
    base = _mm256_blendv_pd(base, _mm256_set1_pd(kAtanQuarters[k]),
                            _mm256_cmp_pd(q, _mm256_set1_pd(static_cast<double>(k)), _CMP_EQ_OQ));
  return _mm256_add_pd(base, _mm256_add_pd(u, _mm256_mul_pd(_mm256_mul_pd(u, w), s)));
}

// series_acos per lane.
__attribute__((target("avx2"))) inline __m256d series_acos4(__m256d x) {
  const __m256d sign = _mm256_set1_pd(-0.0), one = _mm256_set1_pd(1.0);
  const __m256d a = _mm256_andnot_pd(sign, x);
  const __m256d half = atan_unit4(_mm256_sqrt_pd(_mm256_div_pd(_mm256_sub_pd(one, a), _mm256_add_pd(one, a))));
  const __m256d twice = _mm256_mul_pd(_mm256_set1_pd(2.0), half);
  return _mm256_blendv_pd(twice, _mm256_sub_pd(_mm256_set1_pd(M_PI), twice),
                          _mm256_cmp_pd(x, _mm256_setzero_pd(), _CMP_LT_OQ));
}

// series_atan2_double per lane (lanes where x and y are both zero: NaN).
__attribute__((target("avx2"))) inline __m256d series_atan2_double4(__m256d y, __m256d x) {
  const __m256d sign = _mm256_set1_pd(-0.0), zero = _mm256_setzero_pd();
  const __m256d ay = _mm256_andnot_pd(sign, y), ax = _mm256_andnot_pd(sign, x);
  const __m256d steep = _mm256_cmp_pd(ay, ax, _CMP_GT_OQ);
  __m256d r = atan_unit4(_mm256_div_pd(_mm256_blendv_pd(ay, ax, steep), _mm256_blendv_pd(ax, ay, steep)));
  r = _mm256_blendv_pd(r, _mm256_sub_pd(_mm256_set1_pd(M_PI / 2), r), steep);
  r = _mm256_blendv_pd(r, _mm256_sub_pd(_mm256_set1_pd(M_PI), r), _mm256_cmp_pd(x, zero, _CMP_LT_OQ));
  return _mm256_blendv_pd(r, _mm256_xor_pd(r, sign), _mm256_cmp_pd(y, zero, _CMP_LT_OQ));
}

}  // namespace pb
