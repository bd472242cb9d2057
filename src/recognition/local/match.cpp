// Descriptor matching index over the descriptors of all training views:
// exact nearest neighbours under squared L2 distance (ties: the lower row),
// found by a scan with a lower bound, for FPFH (33) and SHOT (352) alike.
// Every descriptor is also projected on the first principal axes of the
// indexed rows (an orthonormal basis P, so |P q - P d| <= |q - d| for every
// pair). The bounds |Pq|^2 + |Pd|^2 - 2 Pq.Pd of a block of queries to every
// row come, for long rows, from long_bounds (AVX2 where the CPU has it, the
// same bits), for short rows from Eigen's blocked product or, with AVX2, from
// short_bounds_avx2 query by query, over the projections stored axis by
// axis; rows are
// then measured exactly in the order of their bounds until the bound exceeds
// the k-th best exact distance (or the threshold), with a margin for the
// product's rounding. Every row that can be among the k nearest is measured
// exactly and offered in ascending row order, so the result is the exact
// scan's, bit for bit. Approximate on request (max_checks > 0): at most that
// many rows, those of the lowest bounds, are measured exactly per query; the
// answer is still exact whenever the early exit comes first (measured
// recall: LocalSettings' match_max_checks). Searches are const and
// thread-safe, and deterministic (no randomized trees).
//
// Why no kd-tree: for SHOT one visits nearly every leaf (measured: no faster
// than a linear scan). FPFH used FLANN's single kd-tree (the index
// pcl::KdTreeFLANN builds) until it measured slower than this scan: 3 times
// on Figure 4.11's noisy table frames, where a query far from every model
// descriptor visits most leaves, 1.3 times on its warehouse frames and 1.8
// times on bench_local's table image (results/bench/README.md, twelfth
// round). The kd-tree also broke exact ties by its own traversal order:
// training views can hold identical descriptors (seen: equal distances to
// rows 424 or 848 apart on Table 4.1's Astra images), and a scene keypoint
// matched whichever of them the tree met first; here the lowest row wins.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "core/cpu.h"
#include "recognition/local/internal.h"

namespace pb::local {

namespace {
// Principal axes of the lower bound: 32 for long rows (SHOT: match_max_checks'
// measured recall is that of these bounds), 12 for short ones (FPFH). Fewer
// axes make the product cheaper and the bound looser; FPFH's match stage on
// bench_local's table image took 2.8 / 1.9 / 1.8 / 2.1 / 2.5 ms with 32 / 16 /
// 12 / 8 / 6 axes (results/bench/README.md, twelfth round).
constexpr int kProjDim = 32;
constexpr int kProjDimShort = 12;
constexpr int kShortRows = 64;  // rows of at most this many values are short
constexpr size_t kPcaRows = 1000;  // at most this many (evenly spaced) rows estimate the axes
using RowMat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}

struct DescriptorIndex::Impl {
  std::vector<float> data;
  float max_sq_norm = 0;       // of the rows (the bound's rounding margin)
  int dim = 0;
  size_t rows = 0;
  int proj_dim = 0;
  std::vector<float> basis;    // proj_dim x dim, orthonormal rows (principal axes)
  std::vector<float> proj;     // rows x proj_dim: each row projected on the basis
  std::vector<float> proj_sq;  // squared norm of each projected row
  std::vector<float> proj_t;   // proj_dim x rows, the projections axis by axis
  bool avx2_bounds = false;    // bounds from short_bounds_avx2 / long_bounds_avx2
};

DescriptorIndex::DescriptorIndex() : impl_(new Impl) {}
DescriptorIndex::~DescriptorIndex() = default;

void DescriptorIndex::build(const std::vector<float>& data, int dim) {
  impl_.reset(new Impl);
  if (dim <= 0 || data.empty()) return;
  impl_->data = data;
  impl_->dim = dim;
  impl_->rows = data.size() / static_cast<size_t>(dim);
  for (size_t r = 0; r < impl_->rows; ++r) {
    const float* d = impl_->data.data() + r * static_cast<size_t>(dim);
    float s = 0;
    for (int j = 0; j < dim; ++j) s += d[j] * d[j];
    impl_->max_sq_norm = std::max(impl_->max_sq_norm, s);
  }
  build_projection();
}

// The kProjDim principal axes of (up to kPcaRows evenly spaced) rows, in
// double (orthonormal to ~1e-15 before rounding to float), and every row's
// projection on them.
void DescriptorIndex::build_projection() {
  Impl& m = *impl_;
  const Eigen::Index dim = m.dim;
  const size_t step = std::max<size_t>(1, (m.rows + kPcaRows - 1) / kPcaRows);
  const Eigen::Index used = static_cast<Eigen::Index>((m.rows + step - 1) / step);
  Eigen::MatrixXd X(used, dim);
  for (Eigen::Index i = 0; i < used; ++i)
    for (Eigen::Index j = 0; j < dim; ++j) X(i, j) = m.data[static_cast<size_t>(i) * step * dim + j];
  X.rowwise() -= X.colwise().mean();
  const Eigen::MatrixXd C = X.transpose() * X;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(C);
  m.proj_dim = static_cast<int>(std::min<Eigen::Index>(dim > kShortRows ? kProjDim : kProjDimShort, dim));
  m.basis.resize(static_cast<size_t>(m.proj_dim) * dim);
  for (int a = 0; a < m.proj_dim; ++a)  // eigenvalues ascend: the largest last
    for (Eigen::Index j = 0; j < dim; ++j)
      m.basis[static_cast<size_t>(a) * dim + j] = static_cast<float>(es.eigenvectors()(j, dim - 1 - a));
  const Eigen::Map<const RowMat> D(m.data.data(), static_cast<Eigen::Index>(m.rows), dim);
  const Eigen::Map<const RowMat> B(m.basis.data(), m.proj_dim, dim);
  const RowMat Z = D * B.transpose();
  m.proj.assign(Z.data(), Z.data() + Z.size());
  m.proj_sq.resize(m.rows);
  for (size_t r = 0; r < m.rows; ++r) m.proj_sq[r] = Z.row(static_cast<Eigen::Index>(r)).squaredNorm();
  m.proj_t.resize(static_cast<size_t>(m.proj_dim) * m.rows);
  for (size_t r = 0; r < m.rows; ++r)
    for (int a = 0; a < m.proj_dim; ++a)
      m.proj_t[static_cast<size_t>(a) * m.rows + r] = Z(static_cast<Eigen::Index>(r), a);
  m.avx2_bounds = cpu_has_avx2();
}

void DescriptorIndex::set_avx2_bounds(bool on) { impl_->avx2_bounds = on && !impl_->proj_t.empty() && cpu_has_avx2(); }

size_t DescriptorIndex::size() const { return impl_->rows; }

namespace {

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

// The first index of the smallest of v[0..n) (n > 0; as the scan `if (v[r] <
// v[arg]) arg = r`, for finite values). Four lanes of SSE minima find the
// value (a minimum is exact in any order), a scan its first index.
inline size_t first_argmin(const float* v, size_t n) {
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

// Appends (v[r], r) for every r < n with v[r] <= limit, in ascending r
// (SSE: four values compared at once, most blocks have none).
inline void append_at_most(const float* v, size_t n, float limit, std::vector<std::pair<float, int>>& out) {
  size_t r = 0;
#ifdef __SSE2__
  const __m128 l4 = _mm_set1_ps(limit);
  for (; r + 4 <= n; r += 4) {
    const int mask = _mm_movemask_ps(_mm_cmple_ps(_mm_loadu_ps(v + r), l4));
    if (mask == 0) continue;
    for (int k = 0; k < 4; ++k)
      if (mask & (1 << k)) out.emplace_back(v[r + k], static_cast<int>(r + k));
  }
#endif
  for (; r < n; ++r)
    if (v[r] <= limit) out.emplace_back(v[r], static_cast<int>(r));
}

// Keeps the kk smallest (distance, then row) of the candidates offered, in
// ascending order; rows arrive ascending, so equal distances keep the lower row.
inline void offer(std::vector<std::pair<int, float>>& out, size_t kk, int row, float s) {
  if (out.size() == kk) {
    if (!(s < out.back().second)) return;
    out.pop_back();
  }
  const std::pair<int, float> e(row, s);
  out.insert(std::upper_bound(out.begin(), out.end(), e,
                              [](const auto& a, const auto& b) { return a.second < b.second; }),
             e);
}

#if defined(__x86_64__) || defined(__i386__)
// The lower bounds |Pq|^2 + |Pd|^2 - 2 Pq.Pd of one query (projection zq,
// its squared norm zn) to every row, eight rows at a time: zt holds the
// rows' projections axis by axis (kProjDimShort x rows). Another rounding
// than Eigen's product, inside the margin knn_block allows for it.
__attribute__((target("avx2"))) void short_bounds_avx2(const float* zq, float zn, const float* zt, const float* psq,
                                                       size_t rows, float* lbs) {
  __m256 q[kProjDimShort];
  for (int a = 0; a < kProjDimShort; ++a) q[a] = _mm256_set1_ps(-2.f * zq[a]);
  const __m256 n8 = _mm256_set1_ps(zn);
  size_t r = 0;
  for (; r + 8 <= rows; r += 8) {
    __m256 acc = _mm256_add_ps(n8, _mm256_loadu_ps(psq + r));
    for (int a = 0; a < kProjDimShort; ++a)
      acc = _mm256_add_ps(acc, _mm256_mul_ps(q[a], _mm256_loadu_ps(zt + static_cast<size_t>(a) * rows + r)));
    _mm256_storeu_ps(lbs + r, acc);
  }
  for (; r < rows; ++r) {
    float acc = zn + psq[r];
    for (int a = 0; a < kProjDimShort; ++a) acc += -2.f * zq[a] * zt[static_cast<size_t>(a) * rows + r];
    lbs[r] = acc;
  }
}

// The lower bounds of long rows (SHOT's 32 axes), eight rows at a time: the
// same values as long_bounds (below), bit for bit (each lane does the same
// float operations in the same order; no fused multiply-add). Rows in tiles
// that stay in the L1 cache; four queries share each load of a tile's
// projections.
__attribute__((target("avx2"))) void long_bounds_avx2(const float* zq, const float* zn, int nq, int pd,
                                                      const float* zt, const float* psq, size_t rows, float* lbs) {
  constexpr size_t kTile = 256;  // rows: 32 axes x 256 rows x 4 bytes = 32 KB
  const __m256 two = _mm256_set1_ps(2.f);
  __m256 qb[4 * kProjDim];  // pd <= kProjDim
  for (size_t t0 = 0; t0 < rows; t0 += kTile) {
    const size_t t1 = std::min(rows, t0 + kTile);
    int i = 0;
    for (; i + 4 <= nq; i += 4) {
      const float* q = zq + static_cast<size_t>(i) * pd;
      const size_t P = static_cast<size_t>(pd);
      // The four queries' coordinates, each broadcast once per tile (axis by
      // axis, query by query): the products read them from memory.
      for (size_t a = 0; a < P; ++a)
        for (size_t j = 0; j < 4; ++j) qb[4 * a + j] = _mm256_set1_ps(q[j * P + a]);
      size_t r = t0;
      for (; r + 8 <= t1; r += 8) {
        __m256 z = _mm256_loadu_ps(zt + r);
        __m256 d0 = _mm256_mul_ps(qb[0], z), d1 = _mm256_mul_ps(qb[1], z), d2 = _mm256_mul_ps(qb[2], z),
               d3 = _mm256_mul_ps(qb[3], z);
        for (size_t a = 1; a < P; ++a) {
          z = _mm256_loadu_ps(zt + a * rows + r);
          const __m256* b = qb + 4 * a;
          d0 = _mm256_add_ps(d0, _mm256_mul_ps(b[0], z));
          d1 = _mm256_add_ps(d1, _mm256_mul_ps(b[1], z));
          d2 = _mm256_add_ps(d2, _mm256_mul_ps(b[2], z));
          d3 = _mm256_add_ps(d3, _mm256_mul_ps(b[3], z));
        }
        const __m256 p = _mm256_loadu_ps(psq + r);
        const __m256 d[4] = {d0, d1, d2, d3};
        for (int j = 0; j < 4; ++j)
          _mm256_storeu_ps(lbs + static_cast<size_t>(i + j) * rows + r,
                           _mm256_sub_ps(_mm256_add_ps(_mm256_set1_ps(zn[i + j]), p), _mm256_mul_ps(two, d[j])));
      }
      for (; r < t1; ++r)
        for (int j = 0; j < 4; ++j) {
          const float* qj = q + static_cast<size_t>(j) * P;
          float d = qj[0] * zt[r];
          for (size_t a = 1; a < P; ++a) d = d + qj[a] * zt[a * rows + r];
          lbs[static_cast<size_t>(i + j) * rows + r] = (zn[i + j] + psq[r]) - 2.f * d;
        }
    }
    for (; i < nq; ++i) {  // the last queries one at a time
      const float* q = zq + static_cast<size_t>(i) * pd;
      size_t r = t0;
      for (; r + 8 <= t1; r += 8) {
        __m256 d = _mm256_mul_ps(_mm256_set1_ps(q[0]), _mm256_loadu_ps(zt + r));
        for (int a = 1; a < pd; ++a) {
          const __m256 z = _mm256_loadu_ps(zt + static_cast<size_t>(a) * rows + r);
          d = _mm256_add_ps(d, _mm256_mul_ps(_mm256_set1_ps(q[a]), z));
        }
        const __m256 base = _mm256_add_ps(_mm256_set1_ps(zn[i]), _mm256_loadu_ps(psq + r));
        _mm256_storeu_ps(lbs + static_cast<size_t>(i) * rows + r, _mm256_sub_ps(base, _mm256_mul_ps(two, d)));
      }
      for (; r < t1; ++r) {
        float d = q[0] * zt[r];
        for (int a = 1; a < pd; ++a) d = d + q[a] * zt[static_cast<size_t>(a) * rows + r];
        lbs[static_cast<size_t>(i) * rows + r] = (zn[i] + psq[r]) - 2.f * d;
      }
    }
  }
}
#else
void short_bounds_avx2(const float*, float, const float*, const float*, size_t, float*) {}
void long_bounds_avx2(const float*, const float*, int, int, const float*, const float*, size_t, float*) {}
#endif

// The lower bounds of long rows, for the `nq` queries of a block (projections
// zq, nq x pd; squared norms zn) to every row, written to lbs (nq x rows): zt
// holds the rows' projections axis by axis (pd x rows). Each dot product is
// summed over the axes in ascending order, a product then an add, and the
// bound is (zn + psq) - 2 dot. One order for every path, because the capped
// search (max_checks) ranks rows by these values: the AVX2 kernel and this
// loop give the same matches. (Eigen's product, used before, sums the rows
// left over from its 12-row panels in another order.)
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

}  // namespace

// The `cap` smallest (v[r], r) pairs (value, then index) among those with
// v[r] <= limit, in any order: what taking every such pair and keeping the
// cap smallest with nth_element gives, without building the full list (a
// noisy query has thousands of rows under its limit). A max-heap of the cap
// best so far; a value is offered only when it is below the heap's top
// (rows arrive ascending, so an equal value loses to the row already kept),
// found four at a time by SSE.
void smallest_at_most(const float* v, size_t n, float limit, size_t cap,
                      std::vector<std::pair<float, int>>& heap) {
  heap.clear();
  if (cap == 0) return;
  const auto offer_row = [&](size_t r) {
    const std::pair<float, int> e(v[r], static_cast<int>(r));
    if (!(e.first <= limit)) return;  // NaN too
    if (heap.size() < cap) {
      heap.push_back(e);
      std::push_heap(heap.begin(), heap.end());
    } else if (e < heap.front()) {
      std::pop_heap(heap.begin(), heap.end());
      heap.back() = e;
      std::push_heap(heap.begin(), heap.end());
    }
  };
  size_t r = 0;
#ifdef __SSE2__
  // Below the bar: at most the limit while the heap fills, then at most its
  // top (re-read only when the heap changes).
  __m128 bar = _mm_set1_ps(limit);
  for (; r + 4 <= n; r += 4) {
    const int mask = _mm_movemask_ps(_mm_cmple_ps(_mm_loadu_ps(v + r), bar));
    if (mask == 0) continue;
    for (int k = 0; k < 4; ++k)
      if (mask & (1 << k)) offer_row(r + static_cast<size_t>(k));
    if (heap.size() == cap) bar = _mm_set1_ps(heap.front().first);
  }
#endif
  for (; r < n; ++r) offer_row(r);
}

void DescriptorIndex::bounds(const float* queries, int n, float* lbs) const {
  const Impl& m = *impl_;
  const Eigen::Index dim = m.dim;
  const Eigen::Map<const RowMat> Q(queries, n, dim);
  const Eigen::Map<const RowMat> B(m.basis.data(), m.proj_dim, dim);
  const RowMat Zq = Q * B.transpose();  // n x proj_dim
  std::vector<float> zn(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) zn[static_cast<size_t>(i)] = Zq.row(i).squaredNorm();
  // Long rows: long_bounds, or its AVX2 kernel (the same bits). Short rows:
  // the AVX2 kernel query by query, or Eigen's n x rows product of the
  // projections, then the bounds in place (short rows are searched exactly:
  // their rounding does not matter).
  if (m.dim > kShortRows) {
    (m.avx2_bounds ? long_bounds_avx2 : long_bounds)(Zq.data(), zn.data(), n, m.proj_dim, m.proj_t.data(),
                                                     m.proj_sq.data(), m.rows, lbs);
  } else if (m.avx2_bounds && m.proj_dim == kProjDimShort) {
    for (int i = 0; i < n; ++i)
      short_bounds_avx2(Zq.row(i).data(), zn[static_cast<size_t>(i)], m.proj_t.data(), m.proj_sq.data(), m.rows,
                        lbs + static_cast<size_t>(i) * m.rows);
  } else {
    Eigen::Map<RowMat> G(lbs, n, static_cast<Eigen::Index>(m.rows));
    const Eigen::Map<const RowMat> Z(m.proj.data(), static_cast<Eigen::Index>(m.rows), m.proj_dim);
    G.noalias() = Zq * Z.transpose();
    for (int i = 0; i < n; ++i) {
      float* g = lbs + static_cast<size_t>(i) * m.rows;
      const float zni = zn[static_cast<size_t>(i)];
      for (size_t r = 0; r < m.rows; ++r) g[r] = zni + m.proj_sq[r] - 2.f * g[r];  // branch-free: vectorized
    }
  }
}

std::vector<float> DescriptorIndex::lower_bounds(const float* queries, int n) const {
  std::vector<float> lbs(static_cast<size_t>(n) * impl_->rows);
  if (!lbs.empty()) bounds(queries, n, lbs.data());
  return lbs;
}

void DescriptorIndex::knn_block(const float* queries, int n, int k, float max_sq_dist,
                                std::vector<std::pair<int, float>>* out, int max_checks) const {
  const size_t dim = static_cast<size_t>(impl_->dim);
  if (impl_->rows == 0 || k <= 0) {
    for (int i = 0; i < n; ++i) out[i].clear();
    return;
  }
  const Impl& m = *impl_;
  const size_t kk = std::min<size_t>(static_cast<size_t>(k), m.rows);
  const std::unique_ptr<float[]> all(new float[static_cast<size_t>(n) * m.rows]);  // every one written
  bounds(queries, n, all.get());
  const auto dist = m.avx2_bounds ? sq_dist_avx2 : sq_dist;  // the same bits
  std::vector<std::pair<float, int>> cand;
  std::vector<std::pair<int, float>> best, measured;
  for (int i = 0; i < n; ++i) {
    out[i].clear();
    const float* q = queries + static_cast<size_t>(i) * dim;
    float qn = 0;
    for (size_t j = 0; j < dim; ++j) qn += q[j] * q[j];
    // Rounding margin of the product form and of the float basis: generous.
    const float margin = 1e-4f * (qn + m.max_sq_norm) + 1e-30f;
    // First pass: the kk smallest bounds; their exact distances cap the k-th
    // best (tau0), so only rows with a bound up to tau0 remain candidates.
    const float* lbs = all.get() + static_cast<size_t>(i) * m.rows;
    cand.clear();
    if (kk == 1) {  // the smallest bound, the lowest row among equal ones
      const size_t arg = first_argmin(lbs, m.rows);
      cand.emplace_back(lbs[arg], static_cast<int>(arg));
    } else {
      for (size_t r = 0; r < m.rows; ++r) {
        const float lb = lbs[r];
        if (cand.size() == kk && !(lb < cand.back().first)) continue;
        if (cand.size() == kk) cand.pop_back();
        cand.insert(std::upper_bound(cand.begin(), cand.end(), std::make_pair(lb, static_cast<int>(r))),
                    {lb, static_cast<int>(r)});
      }
    }
    float tau0 = 0;
    for (const auto& c : cand)
      tau0 = std::max(tau0, dist(q, m.data.data() + static_cast<size_t>(c.second) * dim, dim));
    const float limit = std::min(tau0, max_sq_dist) + margin;
    // Second pass: the candidates, measured in the order of their bounds.
    cand.clear();
    if (max_checks > 0)  // approximate: the lowest bounds
      smallest_at_most(lbs, m.rows, limit, static_cast<size_t>(max_checks), cand);
    else
      append_at_most(lbs, m.rows, limit, cand);
    std::sort(cand.begin(), cand.end());
    best.clear();
    measured.clear();
    for (const auto& [lb, r] : cand) {
      const float tau = best.size() == kk ? best.back().second : max_sq_dist;
      if (lb > tau + margin) break;  // no later row can enter the k nearest
      const float s = dist(q, m.data.data() + static_cast<size_t>(r) * dim, dim);
      if (!(s < max_sq_dist)) continue;
      offer(best, kk, r, s);
      measured.emplace_back(r, s);
    }
    std::sort(measured.begin(), measured.end());  // ascending rows: as the full scan
    for (const auto& [r, s] : measured) offer(out[i], kk, r, s);
  }
}

void DescriptorIndex::knn(const float* query, int k, float max_sq_dist,
                          std::vector<std::pair<int, float>>& out) const {
  // Exact linear scan; keeps the kk best under the threshold.
  out.clear();
  if (impl_->rows == 0 || k <= 0) return;
  const size_t kk = std::min<size_t>(static_cast<size_t>(k), impl_->rows);
  const size_t dim = static_cast<size_t>(impl_->dim);
  const float* d = impl_->data.data();
  for (size_t r = 0; r < impl_->rows; ++r, d += dim) {
    const float s = sq_dist(query, d, dim);
    if (s < max_sq_dist) offer(out, kk, static_cast<int>(r), s);
  }
}

}  // namespace pb::local
