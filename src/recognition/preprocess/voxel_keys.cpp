// The voxel grid's packed cell keys, one point and four points at a time
// (voxel_keys.h).
#include "recognition/preprocess/voxel_keys.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/cpu.h"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#define PB_VOXEL_KEYS_X86 1
#endif

namespace pb::detail {

namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "points are read as packed float triples");

// The grid per coordinate (x, y, z) instead of per key field.
struct AxisGrid {
  double leaf, inv;
  int64_t lo[3];
  int shift[3];
};

AxisGrid by_axis(const PackedGrid& g) {
  AxisGrid a{g.leaf, 1.0 / g.leaf, {0, 0, 0}, {0, 0, 0}};
  for (int f = 0; f < 3; ++f) {
    a.lo[g.axis[f]] = g.lo[f];
    a.shift[g.axis[f]] = g.shift[f];
  }
  return a;
}

template <bool kDivide>
void keys_scalar(const Vec3f* p, size_t i, size_t n, const AxisGrid& a, uint64_t* keys) {
  for (; i < n; ++i) {
    const Vec3f& q = p[i];
    if (!q.allFinite()) {
      keys[i] = kNoCell;
      continue;
    }
    uint64_t k = 0;
    for (int d = 0; d < 3; ++d) {
      const double v = kDivide ? q[d] / a.leaf : q[d] * a.inv;
      k |= static_cast<uint64_t>(floor_to_int(v) - a.lo[d]) << a.shift[d];
    }
    keys[i] = k;
  }
}

#ifdef PB_VOXEL_KEYS_X86

// The twelve floats of four points at b, in three loads, as an x, a y and a
// z vector (SSE; inlined into the AVX2 kernel as well).
inline void four_points(const float* b, __m128 c[3]) {
  // v0 = x0 y0 z0 x1, v1 = y1 z1 x2 y2, v2 = z2 x3 y3 z3.
  const __m128 v0 = _mm_loadu_ps(b), v1 = _mm_loadu_ps(b + 4), v2 = _mm_loadu_ps(b + 8);
  const __m128 t0 = _mm_shuffle_ps(v0, v1, _MM_SHUFFLE(1, 0, 3, 2));  // z0 x1 y1 z1
  const __m128 t1 = _mm_shuffle_ps(v1, v2, _MM_SHUFFLE(2, 1, 3, 2));  // x2 y2 x3 y3
  const __m128 t2 = _mm_shuffle_ps(v0, t0, _MM_SHUFFLE(0, 2, 0, 1));  // y0 x0 y1 z0
  c[0] = _mm_shuffle_ps(v0, t1, _MM_SHUFFLE(2, 0, 3, 0));             // x0 x1 x2 x3
  c[1] = _mm_shuffle_ps(t2, t1, _MM_SHUFFLE(3, 1, 2, 0));             // y0 y1 y2 y3
  c[2] = _mm_shuffle_ps(t0, v2, _MM_SHUFFLE(3, 0, 3, 0));             // z0 z1 z2 z3
}

// Four points per step (four_points); per coordinate the same double
// product (or quotient) as keys_scalar, floor by roundpd, the integer by truncation (the
// floor is integral and within int32: PackedGrid::int32_cells). Lanes of
// non-finite points get kNoCell. Returns the first point not done.
template <bool kDivide>
__attribute__((target("avx2"))) size_t keys_avx2(const Vec3f* p, size_t n, const AxisGrid& a, uint64_t* keys) {
  if (n < 4) return 0;
  const float* f = p->data();
  const __m256d leaf = _mm256_set1_pd(a.leaf), inv = _mm256_set1_pd(a.inv);
  const __m128 magnitude = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)), inf = _mm_set1_ps(INFINITY);
  const __m128i lo[3] = {_mm_set1_epi32(static_cast<int>(a.lo[0])), _mm_set1_epi32(static_cast<int>(a.lo[1])),
                         _mm_set1_epi32(static_cast<int>(a.lo[2]))};
  const __m128i shift[3] = {_mm_cvtsi32_si128(a.shift[0]), _mm_cvtsi32_si128(a.shift[1]),
                            _mm_cvtsi32_si128(a.shift[2])};
  const __m256i none = _mm256_set1_epi64x(-1);
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    __m128 c[3];
    four_points(f + 3 * i, c);
    __m128 ok = _mm_castsi128_ps(_mm_set1_epi32(-1));
    __m256i key = _mm256_setzero_si256();
    for (int d = 0; d < 3; ++d) {
      ok = _mm_and_ps(ok, _mm_cmplt_ps(_mm_and_ps(c[d], magnitude), inf));  // false for NaN and inf
      __m256d q = _mm256_cvtps_pd(c[d]);
      q = kDivide ? _mm256_div_pd(q, leaf) : _mm256_mul_pd(q, inv);
      const __m128i cell = _mm_sub_epi32(_mm256_cvttpd_epi32(_mm256_floor_pd(q)), lo[d]);
      key = _mm256_or_si256(key, _mm256_sll_epi64(_mm256_cvtepu32_epi64(cell), shift[d]));
    }
    key = _mm256_blendv_epi8(none, key, _mm256_cvtepi32_epi64(_mm_castps_si128(ok)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(keys + i), key);
  }
  return i;
}

#endif

}  // namespace

bool finite_box(const Vec3f* points, size_t n, float lo[3], float hi[3]) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  float l[3] = {kInf, kInf, kInf}, h[3] = {-kInf, -kInf, -kInf};
  size_t i = 0;
#ifdef PB_VOXEL_KEYS_X86
  if (n >= 4) {
    // Four points per step (four_points); a lane of a non-finite point becomes +inf for the minimum and
    // -inf for the maximum (no NaN reaches min or max).
    const float* f = points->data();
    const __m128 magnitude = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff)), inf = _mm_set1_ps(kInf),
                 ninf = _mm_set1_ps(-kInf);
    __m128 mn[3] = {inf, inf, inf}, mx[3] = {ninf, ninf, ninf};
    for (; i + 4 <= n; i += 4) {
      __m128 c[3];
      four_points(f + 3 * i, c);
      __m128 ok = _mm_cmplt_ps(_mm_and_ps(c[0], magnitude), inf);
      ok = _mm_and_ps(ok, _mm_cmplt_ps(_mm_and_ps(c[1], magnitude), inf));
      ok = _mm_and_ps(ok, _mm_cmplt_ps(_mm_and_ps(c[2], magnitude), inf));
      for (int d = 0; d < 3; ++d) {
        const __m128 kept = _mm_and_ps(ok, c[d]);
        mn[d] = _mm_min_ps(mn[d], _mm_or_ps(kept, _mm_andnot_ps(ok, inf)));
        mx[d] = _mm_max_ps(mx[d], _mm_or_ps(kept, _mm_andnot_ps(ok, ninf)));
      }
    }
    for (int d = 0; d < 3; ++d) {
      alignas(16) float a[4], b[4];
      _mm_store_ps(a, mn[d]);
      _mm_store_ps(b, mx[d]);
      for (int k = 0; k < 4; ++k) {
        l[d] = std::min(l[d], a[k]);
        h[d] = std::max(h[d], b[k]);
      }
    }
  }
#endif
  for (; i < n; ++i) {
    const Vec3f& p = points[i];
    if (!p.allFinite()) continue;
    for (int d = 0; d < 3; ++d) {
      l[d] = std::min(l[d], p[d]);
      h[d] = std::max(h[d], p[d]);
    }
  }
  for (int d = 0; d < 3; ++d) {
    lo[d] = l[d];
    hi[d] = h[d];
  }
  return l[0] <= h[0];
}

void packed_cell_keys(const Vec3f* points, size_t n, const PackedGrid& g, uint64_t* keys, KeyIsa isa) {
  const AxisGrid a = by_axis(g);
  size_t i = 0;
#ifdef PB_VOXEL_KEYS_X86
  const bool avx2 = cpu_has_avx2();
  if (avx2 && isa == KeyIsa::best && g.int32_cells)
    i = g.divide ? keys_avx2<true>(points, n, a, keys) : keys_avx2<false>(points, n, a, keys);
#endif
  if (g.divide) keys_scalar<true>(points, i, n, a, keys);
  else keys_scalar<false>(points, i, n, a, keys);
}

}  // namespace pb::detail
