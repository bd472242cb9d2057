// Descriptor matching index over the descriptors of all training views:
// exact nearest neighbours under squared L2 distance (ties: the lower row),
// found by a scan with a lower bound, for FPFH (33) and SHOT (352) alike.
// Every descriptor is also projected on the first principal axes of the
// indexed rows (an orthonormal basis P, so |P q - P d| <= |q - d| for every
// pair). The bounds |Pq|^2 + |Pd|^2 - 2 Pq.Pd of the queries to every row
// come, for long rows, from long_bounds (AVX2 where the CPU has it, the same
// bits), for short rows from Eigen's blocked product or, with AVX2 and FMA,
// from short_bounds_fma, over the projections stored axis by axis
// (match_kernels.h). The rows are then scanned in ascending order, and a row
// is measured exactly when its bound is within a margin (for the bounds'
// rounding) of the k-th best exact distance so far or the threshold: every
// row that can be among the k nearest is measured and offered in ascending
// row order, so the result is the exact scan's, bit for bit. Approximate on
// request (max_checks > 0): at most that many rows, those of the lowest
// bounds, are measured exactly per query, in the order of their bounds; the
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

#include "core/cpu.h"
#include "recognition/local/internal.h"
#include "recognition/local/match_kernels.h"

namespace pb::local {

namespace {
// The axes of the bound: kProjDim, kProjDimShort (match_kernels.h).
constexpr int kShortRows = 64;  // rows of at most this many values are short
constexpr size_t kPcaRows = 1000;  // at most this many (evenly spaced) rows estimate the axes
using RowMat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
}

struct DescriptorIndex::Impl {
  std::vector<float> data;
  float max_sq_norm = 0;       // of the rows (the bound's rounding margin)
  bool finite = true;          // every row's squared norm is finite (so is every value)
  int dim = 0;
  size_t rows = 0;
  int proj_dim = 0;
  std::vector<float> basis;    // proj_dim x dim, orthonormal rows (principal axes)
  std::vector<float> proj;     // rows x proj_dim: each row projected on the basis
  std::vector<float> proj_sq;  // squared norm of each projected row
  std::vector<float> proj_t;   // proj_dim x rows, the projections axis by axis
  bool avx2_bounds = false;    // bounds from short_bounds_fma (with FMA) / long_bounds_avx2
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
    impl_->finite = impl_->finite && std::isfinite(s);
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

// The first r in [from, n) with v[r] <= bar (NaN never), or n; SSE: four
// values compared at once, most groups have none.
inline size_t next_at_most(const float* v, size_t from, size_t n, float bar) {
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

// Asks for the cache lines of a row of `dim` floats (a hint: no result
// depends on it).
inline void prefetch_row(const float* row, size_t dim) {
  const char* p = reinterpret_cast<const char*>(row);
  for (size_t b = 0; b < dim * sizeof(float); b += 64) __builtin_prefetch(p + b);
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

}  // namespace

// The `cap` smallest (v[r], r) pairs (value, then index) among those with
// v[r] <= limit, in any order: what taking every such pair and keeping the
// cap smallest with nth_element gives, without building the full list (a
// noisy query has thousands of rows under its limit). Pairs under the bar
// are appended; whenever 2 cap of them are kept, nth_element keeps the cap
// smallest and the bar falls to the largest value kept (a later pair equal
// to it is still appended: the last nth_element decides by index). The bar
// is compared eight values at a time by AVX2 (avx2: the CPU has it), else
// four at a time by SSE (next_at_most). (A max-heap of the cap best,
// updated per pair, took five times as long on the warehouse's SHOT rows.)
void smallest_at_most(const float* v, size_t n, float limit, size_t cap, std::vector<std::pair<float, int>>& out,
                      bool avx2) {
  out.clear();
  if (cap == 0) return;
  float bar = limit;
  const auto keep_smallest = [&] {
    std::nth_element(out.begin(), out.begin() + static_cast<long>(cap - 1), out.end());
    out.resize(cap);
    bar = out[cap - 1].first;  // the largest kept (nth_element puts it at cap - 1)
  };
  // The rows under the bar, in ascending order, found as the exact search's
  // second pass finds them.
  const auto next = avx2 ? next_at_most_avx2 : next_at_most;
  for (size_t r = next(v, 0, n, bar); r < n; r = next(v, r + 1, n, bar)) {
    out.emplace_back(v[r], static_cast<int>(r));
    if (out.size() == 2 * cap) keep_smallest();
  }
  if (out.size() > cap) keep_smallest();
}

bool DescriptorIndex::bounds(const float* queries, int n, float* lbs, float* mins) const {
  const Impl& m = *impl_;
  const Eigen::Index dim = m.dim;
  const Eigen::Map<const RowMat> Q(queries, n, dim);
  const Eigen::Map<const RowMat> B(m.basis.data(), m.proj_dim, dim);
  const RowMat Zq = Q * B.transpose();  // n x proj_dim
  std::vector<float> zn(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) zn[static_cast<size_t>(i)] = Zq.row(i).squaredNorm();
  // Long rows: long_bounds, or its AVX2 kernel (the same bits, and each
  // query's smallest bound where every bound is finite). Short rows: the
  // AVX2 + FMA kernel (with each query's smallest bound), or Eigen's n x
  // rows product of the projections, then the bounds in place (short rows
  // are searched exactly: their rounding does not matter).
  if (m.dim > kShortRows && m.avx2_bounds) {
    // Rows and projections of squared norm under 1e30: no sum overflows and
    // no bound is NaN, so the first row equal to the smallest bound is
    // first_argmin's row.
    const bool finite_bounds = m.finite && m.max_sq_norm < 1e30f &&
                               std::all_of(zn.begin(), zn.end(), [](float v) { return v < 1e30f; });
    long_bounds_avx2(Zq.data(), zn.data(), n, m.proj_dim, m.proj_t.data(), m.proj_sq.data(), m.rows, lbs,
                     mins && finite_bounds ? mins : nullptr);
    return mins && finite_bounds;
  } else if (m.dim > kShortRows) {
    long_bounds(Zq.data(), zn.data(), n, m.proj_dim, m.proj_t.data(), m.proj_sq.data(), m.rows, lbs);
  } else if (m.avx2_bounds && m.proj_dim == kProjDimShort && cpu_has_fma()) {
    std::vector<float> own(mins ? 0 : static_cast<size_t>(n));
    short_bounds_fma(Zq.data(), zn.data(), n, m.proj_t.data(), m.proj_sq.data(), m.rows, lbs,
                     mins ? mins : own.data());
    return mins != nullptr;
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
  return false;
}

std::vector<float> DescriptorIndex::lower_bounds(const float* queries, int n) const {
  std::vector<float> lbs(static_cast<size_t>(n) * impl_->rows);
  if (!lbs.empty()) bounds(queries, n, lbs.data(), nullptr);
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
  // Short rows: the bounds of four queries at a time (4 x rows floats stay in
  // the L2 cache; the warehouse's 17,526 rows for a block of 32 took 2.2 MB).
  // Long rows: the whole block at once, each tile of the rows' projections
  // read for every query of the block (groups of four took 15% longer).
  const int group = m.dim > kShortRows ? n : 4;
  const std::unique_ptr<float[]> all(new float[static_cast<size_t>(group) * m.rows]);  // every one written
  std::vector<float> mins(static_cast<size_t>(group));
  bool have_mins = false;
  const auto dist = m.avx2_bounds ? sq_dist_avx2 : sq_dist;  // the same bits
  std::vector<std::pair<float, int>> cand;
  std::vector<std::pair<int, float>> best, measured;
  // The capped search's second pass for one query: the `max_checks` rows of
  // the lowest bounds up to `limit`, measured in the order of their bounds
  // until no later one can enter the k nearest, then offered in ascending
  // row order.
  const auto capped = [&](const float* q, const float* lbs, float limit, float margin,
                          std::vector<std::pair<int, float>>& result) {
    smallest_at_most(lbs, m.rows, limit, static_cast<size_t>(max_checks), cand, m.avx2_bounds);
    std::sort(cand.begin(), cand.end());
    best.clear();
    measured.clear();
    for (size_t c = 0; c < cand.size(); ++c) {
      const auto [lb, r] = cand[c];
      const float tau = best.size() == kk ? best.back().second : max_sq_dist;
      if (lb > tau + margin) break;  // no later row can enter the k nearest
      // The next candidate's row on its way to the cache while this one is
      // measured (SHOT's rows are 22 cache lines each, far apart).
      if (c + 1 < cand.size()) prefetch_row(m.data.data() + static_cast<size_t>(cand[c + 1].second) * dim, dim);
      const float s = dist(q, m.data.data() + static_cast<size_t>(r) * dim, dim);
      if (!(s < max_sq_dist)) continue;
      offer(best, kk, r, s);
      measured.emplace_back(r, s);
    }
    std::sort(measured.begin(), measured.end());  // ascending rows: as the full scan
    for (const auto& [r, s] : measured) offer(result, kk, r, s);
  };
  for (int i = 0; i < n; ++i) {
    if (i % group == 0)
      have_mins = bounds(queries + static_cast<size_t>(i) * dim, std::min(group, n - i), all.get(), mins.data());
    out[i].clear();
    const float* q = queries + static_cast<size_t>(i) * dim;
    float qn = 0;
    for (size_t j = 0; j < dim; ++j) qn += q[j] * q[j];
    // Rounding margin of the product form and of the float basis: generous.
    const float margin = 1e-4f * (qn + m.max_sq_norm) + 1e-30f;
    // First pass: the kk smallest bounds; their exact distances cap the k-th
    // best (tau0), so only rows with a bound up to tau0 remain candidates.
    const float* lbs = all.get() + static_cast<size_t>(i % group) * m.rows;
    cand.clear();
    if (kk == 1) {  // the smallest bound, the lowest row among equal ones
      size_t arg = m.rows;
      if (have_mins) arg = first_equal_avx2(lbs, m.rows, mins[static_cast<size_t>(i % group)]);
      if (arg == m.rows) arg = first_argmin(lbs, m.rows);  // no minimum given, or none equals it (NaN)
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
    if (max_checks > 0) {
      capped(q, lbs, limit, margin, out[i]);
      continue;
    }
    // Second pass, exact: the rows in ascending order, each measured when
    // its bound is within the margin of the k-th best exact distance so far
    // (the bar only falls). A row passed over has a distance above that k-th
    // best, which the exact scan would not keep either.
    const auto next = m.avx2_bounds ? next_at_most_avx2 : next_at_most;
    float bar = limit;
    for (size_t r = next(lbs, 0, m.rows, bar); r < m.rows; r = next(lbs, r + 1, m.rows, bar)) {
      const float s = dist(q, m.data.data() + r * dim, dim);
      if (!(s < max_sq_dist)) continue;
      offer(out[i], kk, static_cast<int>(r), s);
      if (out[i].size() == kk) bar = std::min(bar, out[i].back().second + margin);
    }
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
