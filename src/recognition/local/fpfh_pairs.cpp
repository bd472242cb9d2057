// FPFH's SPFH pairs eight at a time (local/internal.h spfh_pair_bins): the
// three bins of darboux_pair(p, q) (recognition/darboux.h) as fpfh.cpp's
// count_pair bins them, with the bits of the one-at-a-time path. Each lane
// repeats darboux_pair's float operations in Eigen's order for 3-vectors
// (x x' + (y y' + z z'), norm the root of that sum, cross products
// coefficient by coefficient, the normalization a division per
// coefficient), the bins' double operations and series_atan2's; the file is
// built with -ffp-contract=off. A lane is left to the caller wherever the
// one-at-a-time path would decide on something else: coincident points,
// cosines of equal magnitude or not finite (then darboux_pair's pair is not
// symmetric), a degenerate frame, a zero or non-finite value, an angle bin
// the series' window leaves in doubt. PCL-free.
#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "core/lanes_avx2.h"
#include "core/cpu.h"
#include "recognition/local/internal.h"

namespace pb::local {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "the AVX2 path gathers from Vec3f arrays of stride 3 floats");

// clamped_bin(scaled, bins) (recognition/darboux.h) of four doubles: 0
// unless scaled >= 0, else floor(scaled) at most bins - 1.
__attribute__((target("avx2"))) inline __m128i clamped_bins(__m256d scaled, int bins) {
  const __m128i b = _mm256_cvttpd_epi32(_mm256_floor_pd(scaled));
  const __m128i capped = _mm_min_epi32(b, _mm_set1_epi32(bins - 1));
  const __m256i ge = _mm256_castpd_si256(_mm256_cmp_pd(scaled, _mm256_setzero_pd(), _CMP_GE_OQ));
  const __m128i ok =  // each 64-bit mask's low half
      _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(ge, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7)));
  return _mm_and_si128(capped, ok);
}

// count_pair's bins of f2 and f3 (cosines): clamped_bin(11 ((f + 1) 0.5)),
// four lanes.
__attribute__((target("avx2"))) inline __m128i cosine_bins4(__m128 f) {
  const __m256d one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5), k = _mm256_set1_pd(kSpfhBins);
  return clamped_bins(_mm256_mul_pd(k, _mm256_mul_pd(_mm256_add_pd(_mm256_cvtps_pd(f), one), half)), kSpfhBins);
}
__attribute__((target("avx2"))) inline __m256i cosine_bins(__m256 f) {
  return _mm256_set_m128i(cosine_bins4(_mm256_extractf128_ps(f, 1)), cosine_bins4(_mm256_castps256_ps128(f)));
}

// count_pair's bin of f1 = atan2(y, x): clamped_bin(11 ((f1 + pi) inv_2pi)).
__attribute__((target("avx2"))) inline __m128i angle_bins(__m128 f1) {
  const __m256d scaled = _mm256_mul_pd(
      _mm256_set1_pd(kSpfhBins),
      _mm256_mul_pd(_mm256_add_pd(_mm256_cvtps_pd(f1), _mm256_set1_pd(M_PI)), _mm256_set1_pd(kSpfhInv2Pi)));
  return clamped_bins(scaled, kSpfhBins);
}

__attribute__((target("avx2"))) void spfh_pair_bins_avx2(const PointSet& cloud, int p, const int* partners, size_t n,
                                                         uint8_t* decided, int* bins) {
  const float* pts = cloud.points.front().data();
  const float* nrm = cloud.normals.front().data();
  const Lanes3 p1 = broadcast3(cloud.points[static_cast<size_t>(p)]);
  const Lanes3 n1 = broadcast3(cloud.normals[static_cast<size_t>(p)]);
  const __m256 zero = _mm256_setzero_ps(), sign = _mm256_set1_ps(-0.0f);
  alignas(32) int lane[8], ok[8], b[3][8];
  for (size_t k = 0; k < n; k += 8) {
    const PairLanes pl = pair_lanes<dot>(pts, nrm, partners, k, n, lane, p1, n1);
    Lanes3 d = pl.d;
    const __m256 a1 = _mm256_andnot_ps(sign, pl.c1), a2 = _mm256_andnot_ps(sign, pl.c2);
    // Symmetric pairs only (finite cosines of different magnitude).
    __m256 good = _mm256_and_ps(_mm256_and_ps(finite_lanes(pl.c1), finite_lanes(pl.c2)),
                                _mm256_cmp_ps(a1, a2, _CMP_NEQ_OQ));
    good = _mm256_and_ps(good, _mm256_cmp_ps(pl.length, zero, _CMP_NEQ_OQ));
    const __m256 swap = _mm256_cmp_ps(a1, a2, _CMP_LT_OQ);
    const Lanes3 u = select(swap, pl.n2, n1), target = select(swap, n1, pl.n2);
    d = select(swap, negated(d), d);
    const __m256 f3 = _mm256_blendv_ps(pl.c1, _mm256_xor_ps(pl.c2, sign), swap);
    Lanes3 v = cross(d, u);
    const __m256 vn = _mm256_sqrt_ps(dot(v, v));
    good = _mm256_and_ps(good, _mm256_and_ps(_mm256_cmp_ps(vn, zero, _CMP_NEQ_OQ), finite_lanes(vn)));
    v = {_mm256_div_ps(v.x, vn), _mm256_div_ps(v.y, vn), _mm256_div_ps(v.z, vn)};
    const Lanes3 w = cross(u, v);
    const __m256 f2 = dot(v, target), y = dot(w, target), x = dot(u, target);
    good = _mm256_and_ps(good, _mm256_and_ps(_mm256_and_ps(finite_lanes(f2), finite_lanes(f3)),
                                             _mm256_and_ps(finite_lanes(y), finite_lanes(x))));
    good = _mm256_and_ps(good, _mm256_and_ps(_mm256_cmp_ps(y, zero, _CMP_NEQ_OQ), _mm256_cmp_ps(x, zero, _CMP_NEQ_OQ)));
    __m128 lo_a, hi_a, lo_b, hi_b;
    series_atan2_window(_mm256_castps256_ps128(y), _mm256_castps256_ps128(x), &lo_a, &hi_a);
    series_atan2_window(_mm256_extractf128_ps(y, 1), _mm256_extractf128_ps(x, 1), &lo_b, &hi_b);
    const __m256i b1 = _mm256_set_m128i(angle_bins(lo_b), angle_bins(lo_a));
    const __m256i b1_hi = _mm256_set_m128i(angle_bins(hi_b), angle_bins(hi_a));
    good = _mm256_and_ps(good, _mm256_castsi256_ps(_mm256_cmpeq_epi32(b1, b1_hi)));
    _mm256_store_si256(reinterpret_cast<__m256i*>(ok), _mm256_castps_si256(good));
    _mm256_store_si256(reinterpret_cast<__m256i*>(b[0]), b1);
    _mm256_store_si256(reinterpret_cast<__m256i*>(b[1]), cosine_bins(f2));
    _mm256_store_si256(reinterpret_cast<__m256i*>(b[2]), cosine_bins(f3));
    for (size_t j = 0; j < pl.count; ++j) {
      decided[k + j] = ok[j] != 0;
      bins[3 * (k + j)] = b[0][j];
      bins[3 * (k + j) + 1] = kSpfhBins + b[1][j];
      bins[3 * (k + j) + 2] = 2 * kSpfhBins + b[2][j];
    }
  }
}

}  // namespace

void spfh_pair_bins(const PointSet& cloud, int p, const int* partners, size_t n, uint8_t* decided, int* bins) {
  if (cpu_has_avx2() && n > 0) {
    spfh_pair_bins_avx2(cloud, p, partners, n, decided, bins);
    return;
  }
  std::fill(decided, decided + n, uint8_t{0});  // one at a time, by the caller
}

}  // namespace pb::local
