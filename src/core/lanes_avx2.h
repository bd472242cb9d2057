// Pieces of the kernels that compute pair features eight at a time with
// AVX2 (PPF's pair keys, FPFH's SPFH pairs): 3-vectors of eight lanes,
// Eigen's cross product coefficient by coefficient, and binned_atan2's
// window (core/atan2_bin.h). Include only in files built with
// -ffp-contract=off: the lanes must repeat the scalar operations in their
// order.
#pragma once

#include <immintrin.h>

#include <algorithm>
#include <cstddef>

#include "core/atan2_bin.h"
#include "core/types.h"

namespace pb {

// Eight 3-vectors, a coordinate per register.
struct Lanes3 {
  __m256 x, y, z;
};

// v in every lane.
__attribute__((target("avx2"))) inline Lanes3 broadcast3(const Vec3f& v) {
  return {_mm256_set1_ps(v.x()), _mm256_set1_ps(v.y()), _mm256_set1_ps(v.z())};
}

// a - b, coordinate by coordinate.
__attribute__((target("avx2"))) inline Lanes3 minus(const Lanes3& a, const Lanes3& b) {
  return {_mm256_sub_ps(a.x, b.x), _mm256_sub_ps(a.y, b.y), _mm256_sub_ps(a.z, b.z)};
}

// The block of (at most) eight indices idx[k..n) into lane[], the lanes past
// n repeating idx[k]; returns how many are real.
inline size_t block_of_eight(const int* idx, size_t k, size_t n, int lane[8]) {
  const size_t count = std::min<size_t>(8, n - k);
  for (size_t j = 0; j < 8; ++j) lane[j] = idx[k + (j < count ? j : 0)];
  return count;
}

// Eigen's dot product of 3-vectors (Vector3f), x x' + (y y' + z z').
__attribute__((target("avx2"))) inline __m256 dot(const Lanes3& a, const Lanes3& b) {
  return _mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_add_ps(_mm256_mul_ps(a.y, b.y), _mm256_mul_ps(a.z, b.z)));
}

// Eigen's cross product of 3-vectors, coefficient by coefficient.
__attribute__((target("avx2"))) inline Lanes3 cross(const Lanes3& a, const Lanes3& b) {
  return {_mm256_sub_ps(_mm256_mul_ps(a.y, b.z), _mm256_mul_ps(a.z, b.y)),
          _mm256_sub_ps(_mm256_mul_ps(a.z, b.x), _mm256_mul_ps(a.x, b.z)),
          _mm256_sub_ps(_mm256_mul_ps(a.x, b.y), _mm256_mul_ps(a.y, b.x))};
}

// mask ? a : b, lane by lane.
__attribute__((target("avx2"))) inline Lanes3 select(__m256 mask, const Lanes3& a, const Lanes3& b) {
  return {_mm256_blendv_ps(b.x, a.x, mask), _mm256_blendv_ps(b.y, a.y, mask), _mm256_blendv_ps(b.z, a.z, mask)};
}

// -a, lane by lane (the sign bit flipped).
__attribute__((target("avx2"))) inline Lanes3 negated(const Lanes3& a) {
  const __m256 sign = _mm256_set1_ps(-0.0f);
  return {_mm256_xor_ps(a.x, sign), _mm256_xor_ps(a.y, sign), _mm256_xor_ps(a.z, sign)};
}

// Point i of `xyz` (3 floats apart) in lane j for the indices of `at`.
__attribute__((target("avx2"))) inline Lanes3 gather3(const float* xyz, __m256i index) {
  const __m256i at = _mm256_mullo_epi32(index, _mm256_set1_epi32(3));
  return {_mm256_i32gather_ps(xyz, at, 4), _mm256_i32gather_ps(xyz + 1, at, 4), _mm256_i32gather_ps(xyz + 2, at, 4)};
}

// The common start of a pair feature for a block of eight pairs: the first
// point (p1, n1) in every lane, the second points idx[k..n) (lane[] gets
// the block, block_of_eight) from `pts` and `nrm` (3 floats apart), the
// line d = p2 - p1, its length |d| and the two normals' cosines to it,
// n . d / |d|, each dot product the scalar code's (Dot).
struct PairLanes {
  size_t count;  // real lanes
  Lanes3 n2, d;
  __m256 length, c1, c2;
};
template <__m256 (*Dot)(const Lanes3&, const Lanes3&)>
__attribute__((target("avx2"))) inline PairLanes pair_lanes(const float* pts, const float* nrm, const int* idx,
                                                            size_t k, size_t n, int lane[8], const Lanes3& p1,
                                                            const Lanes3& n1) {
  PairLanes l;
  l.count = block_of_eight(idx, k, n, lane);
  const __m256i at = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(lane));
  l.n2 = gather3(nrm, at);
  l.d = minus(gather3(pts, at), p1);
  l.length = _mm256_sqrt_ps(Dot(l.d, l.d));
  l.c1 = _mm256_div_ps(Dot(n1, l.d), l.length);
  l.c2 = _mm256_div_ps(Dot(l.n2, l.d), l.length);
  return l;
}

// series_atan2(y, x) of four lanes, in double. Lanes with a zero or
// non-finite argument are the caller's to set aside (binned_atan2 takes
// atan2f for them).
__attribute__((target("avx2"))) inline __m256d series_atan2_lanes(__m128 yf, __m128 xf) {
  const __m256d y = _mm256_cvtps_pd(yf), x = _mm256_cvtps_pd(xf);
  const __m256d sign = _mm256_set1_pd(-0.0), zero = _mm256_setzero_pd();
  const __m256d ay = _mm256_andnot_pd(sign, y), ax = _mm256_andnot_pd(sign, x);
  const __m256d steep = _mm256_cmp_pd(ay, ax, _CMP_GT_OQ);
  __m256d t = _mm256_div_pd(_mm256_blendv_pd(ay, ax, steep), _mm256_blendv_pd(ax, ay, steep));
  const __m256d big = _mm256_cmp_pd(t, _mm256_set1_pd(0.41421356237309503), _CMP_GT_OQ);
  const __m256d one = _mm256_set1_pd(1.0);
  t = _mm256_blendv_pd(t, _mm256_div_pd(_mm256_sub_pd(t, one), _mm256_add_pd(t, one)), big);
  const __m256d base = _mm256_blendv_pd(zero, _mm256_set1_pd(M_PI / 4), big);
  const __m256d t2 = _mm256_mul_pd(t, t);
  __m256d s = _mm256_set1_pd(-1.0 / 15);
  for (const double c : {1.0 / 13, -1.0 / 11, 1.0 / 9, -1.0 / 7, 1.0 / 5, -1.0 / 3, 1.0})
    s = _mm256_add_pd(_mm256_mul_pd(s, t2), _mm256_set1_pd(c));
  __m256d r = _mm256_add_pd(base, _mm256_mul_pd(t, s));
  r = _mm256_blendv_pd(r, _mm256_sub_pd(_mm256_set1_pd(M_PI / 2), r), steep);
  r = _mm256_blendv_pd(r, _mm256_sub_pd(_mm256_set1_pd(M_PI), r), _mm256_cmp_pd(x, zero, _CMP_LT_OQ));
  return _mm256_blendv_pd(r, _mm256_xor_pd(r, sign), _mm256_cmp_pd(y, zero, _CMP_LT_OQ));
}

// The two ends of binned_atan2's window about series_atan2_lanes(y, x) as
// floats (static_cast<float>(a -+ kAtan2BinWindow)).
__attribute__((target("avx2"))) inline void series_atan2_window(__m128 yf, __m128 xf, __m128* lo, __m128* hi) {
  const __m256d r = series_atan2_lanes(yf, xf), window = _mm256_set1_pd(kAtan2BinWindow);
  *lo = _mm256_cvtpd_ps(_mm256_sub_pd(r, window));
  *hi = _mm256_cvtpd_ps(_mm256_add_pd(r, window));
}

// All bits set in the lanes where v is finite.
__attribute__((target("avx2"))) inline __m256 finite_lanes(__m256 v) {
  const __m256 abs = _mm256_andnot_ps(_mm256_set1_ps(-0.0f), v);
  return _mm256_cmp_ps(abs, _mm256_set1_ps(3.40282347e+38f), _CMP_LE_OQ);
}

}  // namespace pb
