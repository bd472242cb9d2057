// PPF's scene pair keys (ppf/internal.h pair_keys): one reference point's
// pairs with its partners, eight at a time where the CPU has AVX2, with the
// bits of the one-at-a-time path. Each lane repeats pair_feature_parts'
// float operations in its order (no fused multiply-add: the file is built
// with -ffp-contract=off), the bins' divisions and floors, and
// series_atan2's double operations; a lane goes the one-at-a-time way
// wherever that path would branch on something the lanes do not decide
// alike: PCL's acos test of the source point (cosines within 1e-6), a zero
// or non-finite value, or an angle whose bin the series' window leaves in
// doubt. PCL-free.
#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "core/lanes_avx2.h"
#include "core/cpu.h"
#include "recognition/ppf/internal.h"

namespace pb::ppf {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "the AVX2 path gathers from Vec3f arrays of stride 3 floats");

bool pair_key(const Vec3f& sr, const Vec3f& nr, const Vec3f& p, const Vec3f& n, const float step[4], uint64_t* key) {
  float f[4], y0, x0;
  if (!pair_feature_parts(sr, nr, p, n, f, &y0, &x0)) return false;
  // f[0] = atan2(y0, x0) is finite unless an argument is NaN.
  if (std::isnan(y0) || std::isnan(x0) || !std::isfinite(f[1]) || !std::isfinite(f[2]) || !std::isfinite(f[3]))
    return false;
  *key = pack_key(atan2_bin(y0, x0, step[0]), feature_bin(f[1], step[1]), feature_bin(f[2], step[2]),
                  feature_bin(f[3], step[3]));
  return true;
}

size_t pair_keys_plain(const Vec3f& sr, const Vec3f& nr, const PointSet& scene, const int* partners, size_t n,
                       int self, const float step[4], int* out_point, uint64_t* out_key) {
  size_t m = 0;
  for (size_t j = 0; j < n; ++j) {
    const int i = partners[j];
    if (i == self) continue;
    uint64_t key;
    if (!pair_key(sr, nr, scene.points[static_cast<size_t>(i)], scene.normals[static_cast<size_t>(i)], step, &key))
      continue;
    out_point[m] = i;
    out_key[m++] = key;
  }
  return m;
}

namespace {

// Eigen's Vector4f dot product with a zero fourth lane, (x + z) + (y + 0),
// as pair_feature_parts' dot4.
__attribute__((target("avx2"))) inline __m256 dot4(const Lanes3& a, const Lanes3& b) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_mul_ps(a.z, b.z)),
                       _mm256_add_ps(_mm256_mul_ps(a.y, b.y), _mm256_setzero_ps()));
}

// feature_bin: clamped_bin(floor(f / step)), as int32 lanes.
__attribute__((target("avx2"))) inline __m256i bins(__m256 f, __m256 step) {
  const __m256 b = _mm256_floor_ps(_mm256_div_ps(f, step));
  const __m256 c = _mm256_max_ps(_mm256_set1_ps(-32767.f), _mm256_min_ps(_mm256_set1_ps(32767.f), b));
  return _mm256_cvttps_epi32(c);
}

__attribute__((target("avx2"))) size_t pair_keys_avx2(const Vec3f& sr, const Vec3f& nr, const PointSet& scene,
                                                      const int* partners, size_t n, int self, const float step[4],
                                                      int* out_point, uint64_t* out_key) {
  const float* pts = scene.points.front().data();
  const float* nrm = scene.normals.front().data();
  const Lanes3 p1 = broadcast3(sr), n1 = broadcast3(nr);
  const __m256 zero = _mm256_setzero_ps(), sign = _mm256_set1_ps(-0.0f), one = _mm256_set1_ps(1.0f),
               sure = _mm256_set1_ps(1e-6f);
  const __m256 step0 = _mm256_set1_ps(step[0]), step1 = _mm256_set1_ps(step[1]), step2 = _mm256_set1_ps(step[2]),
               step3 = _mm256_set1_ps(step[3]);
  size_t m = 0;
  alignas(32) int lane[8], ok[8], b[4][8];
  for (size_t k = 0; k < n; k += 8) {
    const PairLanes pl = pair_lanes<dot4>(pts, nrm, partners, k, n, lane, p1, n1);
    Lanes3 d = pl.d;
    // The source point: decided here where the cosines are 1e-6 apart.
    const __m256 a1 = _mm256_andnot_ps(sign, pl.c1), a2 = _mm256_andnot_ps(sign, pl.c2);
    const __m256 swap = _mm256_and_ps(_mm256_cmp_ps(a2, one, _CMP_LE_OQ),
                                      _mm256_cmp_ps(a1, _mm256_sub_ps(a2, sure), _CMP_LT_OQ));
    const __m256 keep = _mm256_and_ps(_mm256_cmp_ps(a1, one, _CMP_LE_OQ),
                                      _mm256_cmp_ps(a2, _mm256_sub_ps(a1, sure), _CMP_LT_OQ));
    __m256 good = _mm256_or_ps(swap, keep);
    good = _mm256_and_ps(good, _mm256_cmp_ps(pl.length, zero, _CMP_NEQ_OQ));
    const Lanes3 u = select(swap, pl.n2, n1), target = select(swap, n1, pl.n2);
    d = select(swap, negated(d), d);
    const __m256 f2 = _mm256_blendv_ps(pl.c1, _mm256_xor_ps(pl.c2, sign), swap);
    Lanes3 v = cross(d, u);
    const __m256 vn = _mm256_sqrt_ps(dot4(v, v));
    good = _mm256_and_ps(good, _mm256_cmp_ps(vn, zero, _CMP_NEQ_OQ));
    v = {_mm256_div_ps(v.x, vn), _mm256_div_ps(v.y, vn), _mm256_div_ps(v.z, vn)};
    const Lanes3 w = cross(u, v);
    const __m256 f1 = dot4(v, target), y = dot4(w, target), x = dot4(u, target);
    good = _mm256_and_ps(good,
                         _mm256_and_ps(_mm256_and_ps(finite_lanes(f1), finite_lanes(f2)), finite_lanes(pl.length)));
    good = _mm256_and_ps(good, _mm256_and_ps(finite_lanes(y), finite_lanes(x)));
    good = _mm256_and_ps(good, _mm256_and_ps(_mm256_cmp_ps(y, zero, _CMP_NEQ_OQ), _mm256_cmp_ps(x, zero, _CMP_NEQ_OQ)));
    // f1's bin from the series where its window leaves no doubt.
    __m128 lo_a, hi_a, lo_b, hi_b;
    series_atan2_window(_mm256_castps256_ps128(y), _mm256_castps256_ps128(x), &lo_a, &hi_a);
    series_atan2_window(_mm256_extractf128_ps(y, 1), _mm256_extractf128_ps(x, 1), &lo_b, &hi_b);
    const __m256i b0 = bins(_mm256_set_m128(lo_b, lo_a), step0);
    good = _mm256_and_ps(good, _mm256_castsi256_ps(_mm256_cmpeq_epi32(b0, bins(_mm256_set_m128(hi_b, hi_a), step0))));
    _mm256_store_si256(reinterpret_cast<__m256i*>(ok), _mm256_castps_si256(good));
    _mm256_store_si256(reinterpret_cast<__m256i*>(b[0]), b0);
    _mm256_store_si256(reinterpret_cast<__m256i*>(b[1]), bins(f1, step1));
    _mm256_store_si256(reinterpret_cast<__m256i*>(b[2]), bins(f2, step2));
    _mm256_store_si256(reinterpret_cast<__m256i*>(b[3]), bins(pl.length, step3));
    for (size_t j = 0; j < pl.count; ++j) {
      const int i = lane[j];
      if (i == self) continue;
      if (ok[j]) {
        out_point[m] = i;
        out_key[m++] = pack_key(b[0][j], b[1][j], b[2][j], b[3][j]);
        continue;
      }
      uint64_t key;  // the lane's doubt: the one-at-a-time path decides
      if (!pair_key(sr, nr, scene.points[static_cast<size_t>(i)], scene.normals[static_cast<size_t>(i)], step, &key))
        continue;
      out_point[m] = i;
      out_key[m++] = key;
    }
  }
  return m;
}

}  // namespace

size_t pair_keys(const Vec3f& sr, const Vec3f& nr, const PointSet& scene, const int* partners, size_t n, int self,
                 const float step[4], int* out_point, uint64_t* out_key) {
  if (cpu_has_avx2() && n > 0)
    return pair_keys_avx2(sr, nr, scene, partners, n, self, step, out_point, out_key);
  return pair_keys_plain(sr, nr, scene, partners, n, self, step, out_point, out_key);
}

}  // namespace pb::ppf
