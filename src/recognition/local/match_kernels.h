// The arithmetic kernels of the descriptor index (match.cpp): squared
// distances and the projected lower bounds, each in a plain version and, on
// x86, an AVX2 one chosen at run time (core/cpu.h). Where a result feeds a
// choice that rounding could change (SHOT's capped search ranks rows by their
// bounds), the AVX2 version does the same float operations in the same order
// per lane, with no fused multiply-add: the same bits.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace pb::local {

// Principal axes of the lower bound: 32 for long rows (SHOT: match_max_checks'
// measured recall is that of these bounds), 12 for short ones (FPFH). Fewer
// axes make the product cheaper and the bound looser; FPFH's match stage on
// bench_local's table image took 2.8 / 1.9 / 1.8 / 2.1 / 2.5 ms with 32 / 16 /
// 12 / 8 / 6 axes (results/bench/README.md).
constexpr int kProjDim = 32;
constexpr int kProjDimShort = 12;

// Squared L2 distance with eight fixed partial sums (vectorizable; the same
// summation order every run, whatever the blocking).
inline float sq_dist(const float* a, const float* b, size_t dim) {
  float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  size_t j = 0;
  for (; j + 8 <= dim; j += 8)
    for (int l = 0; l < 8; ++l) {
      const float t = a[j + l] - b[j + l];
      acc[l] += t * t;
    }
  for (; j < dim; ++j) {
    const float t = a[j] - b[j];
    acc[0] += t * t;
  }
  return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

// sq_dist's value from the eight partial sums in one AVX2 register (plain
// sq_dist where the build is not for x86): the same bits.
float sq_dist_avx2(const float* a, const float* b, size_t dim);

// The lower bounds |Pq|^2 + |Pd|^2 - 2 Pq.Pd of nq queries (projections zq,
// nq x kProjDimShort; squared norms zn) to every row, into lbs (nq x rows),
// and each query's smallest bound into mins, from the rows' projections
// stored axis by axis (zt, kProjDimShort x rows) and their squared norms
// (psq). Only where the CPU has AVX2 and FMA (cpu_has_fma). Fused
// multiply-adds: another rounding than the plain product, which FPFH's exact
// search allows for.
void short_bounds_fma(const float* zq, const float* zn, int nq, const float* zt, const float* psq, size_t rows,
                      float* lbs, float* mins);

// Keeps in `out` (ascending) the kk smallest (bound, row) pairs offered, in
// any order: the search's first pass, over every row's bounds or the
// clusters' (match_clusters.h).
inline void keep_smallest(std::vector<std::pair<float, int>>& out, size_t kk, std::pair<float, int> e) {
  if (out.size() == kk) {
    if (!(e < out.back())) return;
    out.pop_back();
  }
  out.insert(std::upper_bound(out.begin(), out.end(), e), e);
}

// The first index of the smallest of v[0..n) (n > 0; as the scan `if (v[r] <
// v[arg]) arg = r`, for finite values), and the first r in [from, n) with
// v[r] <= bar (NaN never), or n: with SSE where the build has it.
size_t first_argmin(const float* v, size_t n);
size_t next_at_most(const float* v, size_t from, size_t n, float bar);

// The scans of one query's bounds v[0..n) in the exact search, eight at a
// time (only where the CPU has AVX2): the first index r with v[r] == m, and
// the first r in [from, n) with v[r] <= bar (NaN never); n when none.
size_t first_equal_avx2(const float* v, size_t n, float m);
size_t next_at_most_avx2(const float* v, size_t from, size_t n, float bar);

// The lower bounds of long rows, for the `nq` queries of a block (projections
// zq, nq x pd, pd <= kProjDim; squared norms zn) to every row, written to lbs
// (nq x rows): zt holds the rows' projections axis by axis (pd x rows). Each
// dot product is summed over the axes in ascending order, a product then an
// add, and the bound is (zn + psq) - 2 dot. One order for every path, because
// the capped search (max_checks) ranks rows by these values: long_bounds_avx2
// (where the CPU has AVX2) gives the same bits. (Eigen's product sums the
// rows left over from its 12-row panels in another order.)
void long_bounds(const float* zq, const float* zn, int nq, int pd, const float* zt, const float* psq, size_t rows,
                 float* lbs);
// mins (not null): each query's smallest bound (every bound finite: the
// caller's to check) into mins[0..nq), found as the bounds are written.
void long_bounds_avx2(const float* zq, const float* zn, int nq, int pd, const float* zt, const float* psq,
                      size_t rows, float* lbs, float* mins = nullptr);

// long_bounds' bounds of one query (projection zq, pd values; squared norm zn)
// for blocks of eight positions, each block's projections stored together
// (blocks: per block pd x 8 values, axis by axis; squared norms psq by
// position): block ids[i] goes to out[8 i .. 8 i + 8). Each bound is
// long_bounds' bits for that position's row (the same operations in the same
// order); the AVX2 version (only where the CPU has it) gives the same bits.
void long_bounds_blocks(const float* zq, float zn, int pd, const float* blocks, const float* psq,
                        const uint32_t* ids, size_t n, float* out);
void long_bounds_blocks_avx2(const float* zq, float zn, int pd, const float* blocks, const float* psq,
                             const uint32_t* ids, size_t n, float* out);

}  // namespace pb::local
