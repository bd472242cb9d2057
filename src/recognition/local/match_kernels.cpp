// The descriptor index's kernels (match_kernels.h).
#include "recognition/local/match_kernels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif
#ifdef __SSE2__
#include <emmintrin.h>
#endif

namespace pb::local {

// The first index of the smallest of v[0..n) (n > 0; as the scan `if (v[r] <
// v[arg]) arg = r`, for finite values). Four lanes of SSE minima find the
// value (a minimum is exact in any order), a scan its first index.
size_t first_argmin(const float* v, size_t n) {
  float m = std::numeric_limits<float>::infinity();
  size_t r = 0;
#ifdef __SSE2__
  __m128 m0 = _mm_set1_ps(m), m1 = m0;
  for (; r + 8 <= n; r += 8) {
    m0 = _mm_min_ps(m0, _mm_loadu_ps(v + r));
    m1 = _mm_min_ps(m1, _mm_loadu_ps(v + r + 4));
  }
  alignas(16) float lanes[4];
  _mm_store_ps(lanes, _mm_min_ps(m0, m1));
  for (const float l : lanes) m = std::min(m, l);
#endif
  for (; r < n; ++r) m = std::min(m, v[r]);
  size_t i = 0;
#ifdef __SSE2__
  const __m128 m4 = _mm_set1_ps(m);
  for (; i + 4 <= n; i += 4)
    if (_mm_movemask_ps(_mm_cmpeq_ps(_mm_loadu_ps(v + i), m4)) != 0) break;  // the first equal is in v[i..i+4)
#endif
  for (; i < n; ++i)
    if (v[i] == m) return i;
  size_t arg = 0;  // no finite value equals the minimum (NaN or infinity): the plain scan
  for (size_t i = 1; i < n; ++i)
    if (v[i] < v[arg]) arg = i;
  return arg;
}

// The first r in [from, n) with v[r] <= bar (NaN never), or n; SSE: four
// values compared at once, most groups have none.
size_t next_at_most(const float* v, size_t from, size_t n, float bar) {
  size_t r = from;
#ifdef __SSE2__
  const __m128 b4 = _mm_set1_ps(bar);
  for (; r + 4 <= n; r += 4) {
    const int mask = _mm_movemask_ps(_mm_cmple_ps(_mm_loadu_ps(v + r), b4));
    if (mask != 0) return r + static_cast<size_t>(__builtin_ctz(static_cast<unsigned>(mask)));
  }
#endif
  for (; r < n; ++r)
    if (v[r] <= bar) return r;
  return n;
}

#if defined(__x86_64__) || defined(__i386__)
// sq_dist with the eight partial sums in one AVX2 register: each lane does
// the same operations in the same order (no fused multiply-add), so the
// same bits.
__attribute__((target("avx2"))) float sq_dist_avx2(const float* a, const float* b, size_t dim) {
  __m256 acc8 = _mm256_setzero_ps();
  size_t j = 0;
  for (; j + 8 <= dim; j += 8) {
    const __m256 t = _mm256_sub_ps(_mm256_loadu_ps(a + j), _mm256_loadu_ps(b + j));
    acc8 = _mm256_add_ps(acc8, _mm256_mul_ps(t, t));
  }
  float acc[8];
  _mm256_storeu_ps(acc, acc8);
  for (; j < dim; ++j) {
    const float t = a[j] - b[j];
    acc[0] += t * t;
  }
  return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}
#else
float sq_dist_avx2(const float* a, const float* b, size_t dim) { return sq_dist(a, b, dim); }
#endif

#if defined(__x86_64__) || defined(__i386__)
// The lower bounds |Pq|^2 + |Pd|^2 - 2 Pq.Pd of short rows (FPFH's 12
// axes) for nq queries, eight rows at a time with fused multiply-adds, in
// row tiles that stay in the L1 cache, up to four queries sharing each load
// of a tile's projections; also each query's smallest bound. The bound is
// compute-bound: a fused multiply-add halves its operations (another
// rounding than the plain product's, inside the margin knn_block allows
// for; short rows are searched exactly, so their rounding changes no
// answer).
namespace {
template <int G>
__attribute__((target("avx2,fma"))) void short_bounds_group(const float* zq, const float* zn, const float* zt,
                                                             const float* psq, size_t rows, float* lbs,
                                                             float* mins) {
  constexpr size_t kTile = 512;  // rows: 12 axes x 512 rows x 4 bytes = 24 KB
  __m256 qb[kProjDimShort * G];
  for (int a = 0; a < kProjDimShort; ++a)
    for (int j = 0; j < G; ++j) qb[a * G + j] = _mm256_set1_ps(-2.f * zq[j * kProjDimShort + a]);
  __m256 lo[G], n8[G];
  for (int j = 0; j < G; ++j) {
    lo[j] = _mm256_set1_ps(std::numeric_limits<float>::infinity());
    n8[j] = _mm256_set1_ps(zn[j]);
  }
  float tail_min[G];
  for (int j = 0; j < G; ++j) tail_min[j] = std::numeric_limits<float>::infinity();
  for (size_t t0 = 0; t0 < rows; t0 += kTile) {
    const size_t t1 = std::min(rows, t0 + kTile);
    size_t r = t0;
    for (; r + 8 <= t1; r += 8) {
      const __m256 p = _mm256_loadu_ps(psq + r);
      __m256 acc[G];
      for (int j = 0; j < G; ++j) acc[j] = _mm256_add_ps(n8[j], p);
      for (int a = 0; a < kProjDimShort; ++a) {
        const __m256 z = _mm256_loadu_ps(zt + static_cast<size_t>(a) * rows + r);
        for (int j = 0; j < G; ++j) acc[j] = _mm256_fmadd_ps(qb[a * G + j], z, acc[j]);
      }
      for (int j = 0; j < G; ++j) {
        _mm256_storeu_ps(lbs + static_cast<size_t>(j) * rows + r, acc[j]);
        lo[j] = _mm256_min_ps(lo[j], acc[j]);
      }
    }
    for (; r < t1; ++r)
      for (int j = 0; j < G; ++j) {
        float acc = zn[j] + psq[r];
        for (int a = 0; a < kProjDimShort; ++a)
          acc = std::fma(-2.f * zq[j * kProjDimShort + a], zt[static_cast<size_t>(a) * rows + r], acc);
        lbs[static_cast<size_t>(j) * rows + r] = acc;
        tail_min[j] = std::min(tail_min[j], acc);
      }
  }
  for (int j = 0; j < G; ++j) {
    alignas(32) float l[8];
    _mm256_store_ps(l, lo[j]);
    float m = tail_min[j];
    for (const float v : l) m = std::min(m, v);
    mins[j] = m;
  }
}
}  // namespace

__attribute__((target("avx2,fma"))) void short_bounds_fma(const float* zq, const float* zn, int nq, const float* zt,
                                                          const float* psq, size_t rows, float* lbs, float* mins) {
  int i = 0;
  for (; i + 4 <= nq; i += 4)
    short_bounds_group<4>(zq + static_cast<size_t>(i) * kProjDimShort, zn + i, zt, psq, rows,
                          lbs + static_cast<size_t>(i) * rows, mins + i);
  for (; i < nq; ++i)
    short_bounds_group<1>(zq + static_cast<size_t>(i) * kProjDimShort, zn + i, zt, psq, rows,
                          lbs + static_cast<size_t>(i) * rows, mins + i);
}

// The scans of knn_block's exact search over one query's bounds, eight at a
// time (most groups of eight hold no match): the first index of m, and the
// first index from `from` on with v[r] <= bar; n when none.
__attribute__((target("avx2"))) size_t first_equal_avx2(const float* v, size_t n, float m) {
  const __m256 m8 = _mm256_set1_ps(m);
  size_t i = 0;
  for (; i + 8 <= n; i += 8)
    if (_mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(v + i), m8, _CMP_EQ_OQ)) != 0) break;
  for (; i < n; ++i)
    if (v[i] == m) return i;
  return n;
}

__attribute__((target("avx2"))) size_t next_at_most_avx2(const float* v, size_t from, size_t n, float bar) {
  const __m256 b8 = _mm256_set1_ps(bar);
  size_t r = from;
  for (; r + 8 <= n; r += 8) {
    const int mask = _mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(v + r), b8, _CMP_LE_OQ));
    if (mask != 0) return r + static_cast<size_t>(__builtin_ctz(static_cast<unsigned>(mask)));
  }
  for (; r < n; ++r)
    if (v[r] <= bar) return r;
  return n;
}

// The lower bounds of long rows (SHOT's 32 axes) for four queries over R
// groups of eight rows (rows r, r + 8, ...): each lane does the same float
// operations in the same order as long_bounds (below; no fused
// multiply-add), so the same bits. Two groups share each load of a query's
// broadcast coordinate: with one group the kernel waits on its loads.
namespace {
template <int R>
__attribute__((target("avx2"))) inline void long_bounds_rows(const __m256* qb, const float* zn, size_t P,
                                                             const float* zt, const float* psq, size_t rows,
                                                             size_t r, float* lbs, float* lane_min) {
  __m256 d[R][4];
  for (int g = 0; g < R; ++g) {
    const __m256 z = _mm256_loadu_ps(zt + r + 8 * g);
    for (int j = 0; j < 4; ++j) d[g][j] = _mm256_mul_ps(qb[j], z);
  }
  for (size_t a = 1; a < P; ++a) {
    const __m256* b = qb + 4 * a;
    for (int g = 0; g < R; ++g) {
      const __m256 z = _mm256_loadu_ps(zt + a * rows + r + 8 * g);
      for (int j = 0; j < 4; ++j) d[g][j] = _mm256_add_ps(d[g][j], _mm256_mul_ps(b[j], z));
    }
  }
  const __m256 two = _mm256_set1_ps(2.f);
  for (int g = 0; g < R; ++g) {
    const __m256 p = _mm256_loadu_ps(psq + r + 8 * g);
    for (int j = 0; j < 4; ++j) {
      const __m256 b = _mm256_sub_ps(_mm256_add_ps(_mm256_set1_ps(zn[j]), p), _mm256_mul_ps(two, d[g][j]));
      _mm256_storeu_ps(lbs + static_cast<size_t>(j) * rows + r + 8 * g, b);
      if (lane_min) _mm256_storeu_ps(lane_min + 8 * j, _mm256_min_ps(b, _mm256_loadu_ps(lane_min + 8 * j)));
    }
  }
}
}  // namespace

// Rows in tiles that stay in the L1 cache; four queries share each load of
// a tile's projections.
__attribute__((target("avx2"))) void long_bounds_avx2(const float* zq, const float* zn, int nq, int pd,
                                                      const float* zt, const float* psq, size_t rows, float* lbs,
                                                      float* mins) {
  constexpr size_t kTile = 256;  // rows: 32 axes x 256 rows x 4 bytes = 32 KB
  __m256 qb[4 * kProjDim];  // pd <= kProjDim
  // Each query's smallest bound so far, per lane (a minimum is exact in any
  // order); the rows of the scalar tail go to lane 0.
  std::vector<float> lane_min(mins ? 8 * static_cast<size_t>(nq) : 0, std::numeric_limits<float>::infinity());
  for (size_t t0 = 0; t0 < rows; t0 += kTile) {
    const size_t t1 = std::min(rows, t0 + kTile);
    for (int i = 0; i + 4 <= nq; i += 4) {
      const float* q = zq + static_cast<size_t>(i) * pd;
      const size_t P = static_cast<size_t>(pd);
      // The four queries' coordinates, each broadcast once per tile (axis by
      // axis, query by query): the products read them from memory.
      for (size_t a = 0; a < P; ++a)
        for (size_t j = 0; j < 4; ++j) qb[4 * a + j] = _mm256_set1_ps(q[j * P + a]);
      float* out = lbs + static_cast<size_t>(i) * rows;
      float* lm = mins ? lane_min.data() + 8 * static_cast<size_t>(i) : nullptr;
      size_t r = t0;
      for (; r + 16 <= t1; r += 16) long_bounds_rows<2>(qb, zn + i, P, zt, psq, rows, r, out, lm);
      for (; r + 8 <= t1; r += 8) long_bounds_rows<1>(qb, zn + i, P, zt, psq, rows, r, out, lm);
      for (; r < t1; ++r)
        for (int j = 0; j < 4; ++j) {
          const float* qj = q + static_cast<size_t>(j) * P;
          float d = qj[0] * zt[r];
          for (size_t a = 1; a < P; ++a) d = d + qj[a] * zt[a * rows + r];
          const float b = (zn[i + j] + psq[r]) - 2.f * d;
          lbs[static_cast<size_t>(i + j) * rows + r] = b;
          if (lm) lm[8 * j] = std::min(b, lm[8 * j]);
        }
    }
  }
  // The last queries of a block that are not a group of four (at most three
  // per frame): the plain loop, whose bits these are.
  const int grouped = nq / 4 * 4;
  if (grouped < nq)
    long_bounds(zq + static_cast<size_t>(grouped) * pd, zn + grouped, nq - grouped, pd, zt, psq, rows,
                lbs + static_cast<size_t>(grouped) * rows);
  if (!mins) return;
  for (int i = 0; i < nq; ++i) {
    float m = std::numeric_limits<float>::infinity();
    if (i < grouped) {
      for (int l = 0; l < 8; ++l) m = std::min(lane_min[8 * static_cast<size_t>(i) + static_cast<size_t>(l)], m);
    } else {
      const float* b = lbs + static_cast<size_t>(i) * rows;
      for (size_t r = 0; r < rows; ++r) m = std::min(b[r], m);
    }
    mins[i] = m;
  }
}

namespace {
// A block's bounds (zn + psq) - 2 d from its sums d over the axes.
__attribute__((target("avx2"))) inline void finish_block(__m256 d, float zn, const float* psq, float* out) {
  const __m256 b =
      _mm256_sub_ps(_mm256_add_ps(_mm256_set1_ps(zn), _mm256_loadu_ps(psq)), _mm256_mul_ps(_mm256_set1_ps(2.f), d));
  _mm256_storeu_ps(out, b);
}
}  // namespace

// Four blocks at a time (four independent sums over the axes: one sum waits
// on its adds), then the rest one at a time; every lane as long_bounds.
__attribute__((target("avx2"))) void long_bounds_blocks_avx2(const float* zq, float zn, int pd, const float* blocks,
                                                             const float* psq, const uint32_t* ids, size_t n,
                                                             float* out) {
  const size_t P = static_cast<size_t>(pd), B = 8 * P;
  size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    const float* z0 = blocks + ids[i] * B;
    const float* z1 = blocks + ids[i + 1] * B;
    const float* z2 = blocks + ids[i + 2] * B;
    const float* z3 = blocks + ids[i + 3] * B;
    __m256 q = _mm256_set1_ps(zq[0]);
    __m256 d0 = _mm256_mul_ps(q, _mm256_loadu_ps(z0)), d1 = _mm256_mul_ps(q, _mm256_loadu_ps(z1));
    __m256 d2 = _mm256_mul_ps(q, _mm256_loadu_ps(z2)), d3 = _mm256_mul_ps(q, _mm256_loadu_ps(z3));
    for (size_t a = 1; a < P; ++a) {
      q = _mm256_set1_ps(zq[a]);
      d0 = _mm256_add_ps(d0, _mm256_mul_ps(q, _mm256_loadu_ps(z0 + 8 * a)));
      d1 = _mm256_add_ps(d1, _mm256_mul_ps(q, _mm256_loadu_ps(z1 + 8 * a)));
      d2 = _mm256_add_ps(d2, _mm256_mul_ps(q, _mm256_loadu_ps(z2 + 8 * a)));
      d3 = _mm256_add_ps(d3, _mm256_mul_ps(q, _mm256_loadu_ps(z3 + 8 * a)));
    }
    finish_block(d0, zn, psq + 8 * static_cast<size_t>(ids[i]), out + 8 * i);
    finish_block(d1, zn, psq + 8 * static_cast<size_t>(ids[i + 1]), out + 8 * (i + 1));
    finish_block(d2, zn, psq + 8 * static_cast<size_t>(ids[i + 2]), out + 8 * (i + 2));
    finish_block(d3, zn, psq + 8 * static_cast<size_t>(ids[i + 3]), out + 8 * (i + 3));
  }
  for (; i < n; ++i) {
    const float* z = blocks + ids[i] * B;
    __m256 d = _mm256_mul_ps(_mm256_set1_ps(zq[0]), _mm256_loadu_ps(z));
    for (size_t a = 1; a < P; ++a)
      d = _mm256_add_ps(d, _mm256_mul_ps(_mm256_set1_ps(zq[a]), _mm256_loadu_ps(z + 8 * a)));
    finish_block(d, zn, psq + 8 * static_cast<size_t>(ids[i]), out + 8 * i);
  }
}
#else
void long_bounds_blocks_avx2(const float* zq, float zn, int pd, const float* blocks, const float* psq,
                             const uint32_t* ids, size_t n, float* out) {
  long_bounds_blocks(zq, zn, pd, blocks, psq, ids, n, out);
}
void short_bounds_fma(const float*, const float*, int, const float*, const float*, size_t, float*, float*) {}
size_t first_equal_avx2(const float*, size_t n, float) { return n; }
size_t next_at_most_avx2(const float*, size_t, size_t n, float) { return n; }
void long_bounds_avx2(const float*, const float*, int, int, const float*, const float*, size_t, float*, float*) {}
#endif

void long_bounds(const float* zq, const float* zn, int nq, int pd, const float* zt, const float* psq, size_t rows,
                 float* lbs) {
  for (int i = 0; i < nq; ++i) {
    const float* q = zq + static_cast<size_t>(i) * pd;
    float* out = lbs + static_cast<size_t>(i) * rows;
    for (size_t r = 0; r < rows; ++r) out[r] = q[0] * zt[r];
    for (int a = 1; a < pd; ++a) {
      const float qa = q[a];
      const float* z = zt + static_cast<size_t>(a) * rows;
      for (size_t r = 0; r < rows; ++r) out[r] = out[r] + qa * z[r];
    }
    for (size_t r = 0; r < rows; ++r) out[r] = (zn[i] + psq[r]) - 2.f * out[r];
  }
}

void long_bounds_blocks(const float* zq, float zn, int pd, const float* blocks, const float* psq,
                        const uint32_t* ids, size_t n, float* out) {
  const size_t B = 8 * static_cast<size_t>(pd);
  for (size_t i = 0; i < n; ++i)
    for (size_t l = 0; l < 8; ++l) {
      const float* z = blocks + ids[i] * B + l;
      float d = zq[0] * z[0];
      for (int a = 1; a < pd; ++a) d = d + zq[a] * z[8 * static_cast<size_t>(a)];
      out[8 * i + l] = (zn + psq[8 * static_cast<size_t>(ids[i]) + l]) - 2.f * d;
    }
}

}  // namespace pb::local
