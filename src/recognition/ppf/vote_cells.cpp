// PPF voting's inner loop: the accumulator cells of one scene pair's model
// pairs (ppf/internal.h VoteCells), eight at a time where the CPU has AVX2.
// PCL-free.
#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "core/cpu.h"
#include "recognition/ppf/internal.h"

namespace pb::ppf {

namespace {

// wrapped_alpha's tests against -pi and pi, which it makes in double, as
// float tests: float(pi) = 3.14159274 lies above pi and the float below it,
// 3.14159250, below, so for a float a, a < -pi exactly when a <= -float(pi),
// and a > pi exactly when a >= float(pi).
constexpr float kPiF = static_cast<float>(M_PI);
constexpr float kTwoPiF = static_cast<float>(2 * M_PI);
static_assert(static_cast<double>(kPiF) > M_PI, "float(pi) rounds up");

// The cells. With Check, also whether every vote is far from a doubt
// (false: some may not be): its bin value's fraction at least `margin`
// from 0 and from 1, and its alpha at least margin steps from +-pi, where
// the wrap moves the bin by a turn (to or from an edge only where the step
// divides 360 degrees).
template <bool Check>
__attribute__((target("avx2"))) bool cells_avx2(const uint32_t* ref, const float* alpha_m, size_t n,
                                                 float alpha_s, int n_alpha, float step, uint32_t* cells,
                                                 float margin = 0) {
  const __m256 as = _mm256_set1_ps(alpha_s), neg_pi = _mm256_set1_ps(-kPiF), pi = _mm256_set1_ps(kPiF),
               two_pi = _mm256_set1_ps(kTwoPiF);
  const __m256d pi_d = _mm256_set1_pd(M_PI), step_d = _mm256_set1_pd(static_cast<double>(step));
  const __m256i rows = _mm256_set1_epi32(n_alpha), zero = _mm256_setzero_si256(),
                last = _mm256_set1_epi32(n_alpha - 1);
  // The last block of fewer than eight with masked loads and stores (no
  // read or write beyond n).
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256 near_lo = _mm256_set1_ps(margin), near_hi = _mm256_set1_ps(1 - margin),
               wrap_near = _mm256_set1_ps(static_cast<float>(M_PI - margin * static_cast<double>(step)));
  __m256 doubt = _mm256_setzero_ps();
  for (size_t k = 0; k < n; k += 8) {
    const bool full = k + 8 <= n;
    const __m256i mask = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(std::min<size_t>(n - k, 8))), lane);
    const __m256 am = full ? _mm256_loadu_ps(alpha_m + k) : _mm256_maskload_ps(alpha_m + k, mask);
    const __m256i r = full ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ref + k))
                           : _mm256_maskload_epi32(reinterpret_cast<const int*>(ref + k), mask);
    __m256 a = _mm256_sub_ps(am, as);
    const __m256 below = _mm256_cmp_ps(a, neg_pi, _CMP_LE_OQ), above = _mm256_cmp_ps(a, pi, _CMP_GE_OQ);
    a = _mm256_blendv_ps(a, _mm256_add_ps(a, two_pi), below);  // both masks from the unwrapped a: else-if
    a = _mm256_blendv_ps(a, _mm256_sub_ps(a, two_pi), above);
    // alpha_bin_value: float((double(a) + pi) / double(step)), then floor,
    // truncation to int and the clamp of AlphaBins::exact.
    const __m256d lo = _mm256_div_pd(_mm256_add_pd(_mm256_cvtps_pd(_mm256_castps256_ps128(a)), pi_d), step_d);
    const __m256d hi = _mm256_div_pd(_mm256_add_pd(_mm256_cvtps_pd(_mm256_extractf128_ps(a, 1)), pi_d), step_d);
    const __m256 b = _mm256_set_m128(_mm256_cvtpd_ps(hi), _mm256_cvtpd_ps(lo));
    const __m256 v = _mm256_floor_ps(b);
    if (Check) {  // b - v is exact: the fraction
      const __m256 f = _mm256_sub_ps(b, v), abs_a = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a);
      const __m256 near = _mm256_or_ps(
          _mm256_or_ps(_mm256_cmp_ps(f, near_lo, _CMP_LT_OQ), _mm256_cmp_ps(f, near_hi, _CMP_GT_OQ)),
          _mm256_cmp_ps(abs_a, wrap_near, _CMP_GT_OQ));
      doubt = _mm256_or_ps(doubt, full ? near : _mm256_and_ps(near, _mm256_castsi256_ps(mask)));
    }
    const __m256i bin = _mm256_min_epi32(_mm256_max_epi32(_mm256_cvttps_epi32(v), zero), last);
    const __m256i c = _mm256_add_epi32(_mm256_mullo_epi32(r, rows), bin);
    if (full) _mm256_storeu_si256(reinterpret_cast<__m256i*>(cells + k), c);
    else _mm256_maskstore_epi32(reinterpret_cast<int*>(cells + k), mask, c);
  }
  return _mm256_movemask_ps(doubt) == 0;
}

}  // namespace

// checked's margin: alpha_s off by up to 2 * kAtan2BinWindow, the
// subtraction alpha_m - alpha_s and the wrap each rounded by up to half an
// ulp of 2 pi (2.4e-7), so a vote's alpha by under 2 * kAtan2BinWindow +
// 1e-6 and its bin value by that over the step; doubled, and 1e-5 more for
// the bin value's rounding to float (an ulp below 32 is 1.9e-6), whose
// fraction checked tests.
VoteCells::VoteCells(float angle_step, int n_alpha)
    : step_(angle_step),
      n_alpha_(n_alpha),
      edge_margin_(2 * (2 * kAtan2BinWindow + 1e-6) / angle_step + 1e-5),
      bins_(angle_step, n_alpha),
      avx2_(cpu_has_avx2()) {}

void VoteCells::plain(const uint32_t* ref, const float* alpha_m, size_t n, float alpha_s, uint32_t* cells) const {
  for (size_t k = 0; k < n; ++k)
    cells[k] = ref[k] * static_cast<uint32_t>(n_alpha_) +
               static_cast<uint32_t>(bins_(wrapped_alpha(alpha_m[k], alpha_s)));
}

bool VoteCells::checked(const uint32_t* ref, const float* alpha_m, size_t n, float alpha_s,
                        uint32_t* cells) const {
  return avx2_ && cells_avx2<true>(ref, alpha_m, n, alpha_s, n_alpha_, step_, cells, edge_margin_);
}

void VoteCells::operator()(const uint32_t* ref, const float* alpha_m, size_t n, float alpha_s,
                           uint32_t* cells) const {
  if (avx2_) cells_avx2<false>(ref, alpha_m, n, alpha_s, n_alpha_, step_, cells);
  else plain(ref, alpha_m, n, alpha_s, cells);
}

}  // namespace pb::ppf
