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
// Long rows, from kClusterRows on (SHOT's training views), are also grouped
// in clusters of their projections (match_clusters.h): a query's bounds are
// then computed only for the rows whose bound can be among its kk smallest
// (first pass) or up to its limit (second pass), by the triangle inequality
// to the clusters' centroids, with the full computation's bits: the same
// answers, exact and capped. On the warehouse's 13,278 SHOT rows a query
// computed about 260 blocks of eight rows' bounds instead of 1,660
// (results/bench/README.md).
//
// Why no kd-tree: for SHOT one visits nearly every leaf (measured: no faster
// than a linear scan). For FPFH, FLANN's single kd-tree (the index
// pcl::KdTreeFLANN builds) measured slower than this scan: 3 times on
// Figure 4.11's noisy table frames, where a query far from every model
// descriptor visits most leaves, 1.3 times on its warehouse frames and 1.8
// times on bench_local's table image (results/bench/README.md). The kd-tree
// also breaks exact ties by its own traversal order: training views can hold
// identical descriptors (seen: equal distances to rows 424 or 848 apart on
// Table 4.1's Astra images), and a scene keypoint matches whichever of them
// the tree meets first; here the lowest row wins.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "core/cpu.h"
#include "recognition/local/internal.h"
#include "recognition/local/match_clusters.h"
#include "recognition/local/match_kernels.h"

namespace pb::local {

namespace {
// The axes of the bound: kProjDim, kProjDimShort (match_kernels.h).
constexpr int kShortRows = 64;  // rows of at most this many values are short
constexpr size_t kPcaRows = 1000;  // at most this many (evenly spaced) rows estimate the axes
constexpr size_t kClusterRows = 4096;  // long rows: from this many on, bounds only where they can matter
constexpr double kDenseShare = 0.4;    // ... while a query's likely runs span at most this share of the blocks
constexpr int kDenseProbe = 8;         // (judged every this many queries: a multiple of the AVX2 bounds kernel's four)
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
  RowClusters clusters;        // long rows, at least kClusterRows of them, every value finite
  bool use_clusters = false;   // the pruned bounds (match_clusters.h) where there are clusters
  double dense_share = kDenseShare;

  // Whether query q (its distances to the centroids in cq) had better take
  // every row's bound: the work it is likely to need by the clusters, from
  // the best row of its nearest centroid's cluster, is the runs of that
  // row's bound (the first pass) and of the limit its exact distance gives
  // (the second). Where they span more than the dense share of the blocks,
  // yes (on the warehouse, a block of eight bounds took about 15 ns by the
  // clusters and 7.5 ns among every row's, whose loads four queries share).
  bool dense_better(const ClusterQuery& cq, const float* q, float max_sq_dist) const {
    const auto [b, r] = cluster_near_best(clusters, cq);
    const auto d = avx2_bounds ? sq_dist_avx2 : sq_dist;
    const float t = r < 0 ? max_sq_dist : d(q, data.data() + static_cast<size_t>(r) * dim, static_cast<size_t>(dim));
    const size_t reach =
        cluster_reach(clusters, cq, b) + cluster_reach(clusters, cq, std::min(t, max_sq_dist) + cq.margin);
    return static_cast<double>(reach) > dense_share * static_cast<double>(clusters.block_count());
  }

  // The projections of n queries on the basis (n x proj_dim) and, into zn,
  // their squared norms.
  RowMat project(const float* queries, int n, std::vector<float>& zn) const {
    const Eigen::Map<const RowMat> Q(queries, n, dim);
    const Eigen::Map<const RowMat> B(basis.data(), proj_dim, dim);
    RowMat Zq = Q * B.transpose();
    zn.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) zn[static_cast<size_t>(i)] = Zq.row(i).squaredNorm();
    return Zq;
  }
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
  if (dim > kShortRows && m.rows >= kClusterRows && m.finite && m.max_sq_norm < 1e30f) {
    m.clusters = cluster_rows(m.proj.data(), m.proj_sq.data(), m.rows, m.proj_dim);
    m.use_clusters = true;
  }
}

void DescriptorIndex::set_avx2_bounds(bool on) { impl_->avx2_bounds = on && !impl_->proj_t.empty() && cpu_has_avx2(); }

void DescriptorIndex::set_clusters(bool on) { impl_->use_clusters = on && has_clusters(); }

bool DescriptorIndex::has_clusters() const { return impl_->clusters.count() > 0; }

void DescriptorIndex::set_dense_share(double share) { impl_->dense_share = share; }

size_t DescriptorIndex::size() const { return impl_->rows; }

namespace {

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

// knn_block's second pass for one query, over its candidates.
struct SecondPass {
  const float* data;  // the indexed rows
  size_t dim;
  size_t kk;          // neighbours wanted
  float max_sq_dist;  // the threshold
  float (*dist)(const float*, const float*, size_t);
  std::vector<std::pair<int, float>> best, measured;

  // The capped search: its candidates (the `max_checks` rows of the lowest
  // bounds up to the limit) measured in the order of their bounds until no
  // later one can enter the k nearest, then offered in ascending row order.
  void capped(const float* q, float margin, std::vector<std::pair<float, int>>& cand,
              std::vector<std::pair<int, float>>& result) {
    std::sort(cand.begin(), cand.end());
    best.clear();
    measured.clear();
    for (size_t c = 0; c < cand.size(); ++c) {
      const auto [lb, r] = cand[c];
      const float tau = best.size() == kk ? best.back().second : max_sq_dist;
      if (lb > tau + margin) break;  // no later row can enter the k nearest
      // The next candidate's row on its way to the cache while this one is
      // measured (SHOT's rows are 22 cache lines each, far apart).
      if (c + 1 < cand.size()) prefetch_row(data + static_cast<size_t>(cand[c + 1].second) * dim, dim);
      const float s = dist(q, data + static_cast<size_t>(r) * dim, dim);
      if (!(s < max_sq_dist)) continue;
      offer(best, kk, r, s);
      measured.emplace_back(r, s);
    }
    std::sort(measured.begin(), measured.end());  // ascending rows: as the full scan
    for (const auto& [r, s] : measured) offer(result, kk, r, s);
  }

  // The exact search, one row at a time in ascending order: measured when
  // its bound is within the margin of the k-th best exact distance so far
  // (the bar only falls). A row passed over has a distance above that k-th
  // best, which the exact scan would not keep either.
  void consider(const float* q, size_t r, float margin, float& bar, std::vector<std::pair<int, float>>& result) {
    const float s = dist(q, data + r * dim, dim);
    if (!(s < max_sq_dist)) return;
    offer(result, kk, static_cast<int>(r), s);
    if (result.size() == kk) bar = std::min(bar, result.back().second + margin);
  }

  // The largest exact distance of the first pass's candidates: it caps the
  // k-th best.
  float largest_distance(const float* q, const std::vector<std::pair<float, int>>& cand) const {
    float tau0 = 0;
    for (const auto& c : cand) tau0 = std::max(tau0, dist(q, data + static_cast<size_t>(c.second) * dim, dim));
    return tau0;
  }

  // The search over the rows the clusters listed with a bound up to the
  // limit (the others' bounds are above it): capped to the max_checks
  // smallest (value, then row), as smallest_at_most's, else exact in
  // ascending rows.
  void over_listed(const float* q, float margin, float limit, int max_checks,
                   std::vector<std::pair<float, int>>& within, std::vector<std::pair<int, float>>& result) {
    if (max_checks > 0) {
      const size_t cap = static_cast<size_t>(max_checks);
      if (within.size() > cap) {
        std::nth_element(within.begin(), within.begin() + static_cast<long>(cap - 1), within.end());
        within.resize(cap);
      }
      capped(q, margin, within, result);
      return;
    }
    std::sort(within.begin(), within.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
    float bar = limit;
    for (const auto& [lb, r] : within)
      if (lb <= bar) consider(q, static_cast<size_t>(r), margin, bar, result);
  }

  // The search over every row's bound (lbs): capped to the max_checks
  // smallest up to the limit, else exact over the rows whose bound is
  // under the falling bar (cand: a buffer).
  void over_bounds(const float* q, float margin, float limit, int max_checks, const float* lbs, size_t rows,
                   bool avx2, std::vector<std::pair<float, int>>& cand, std::vector<std::pair<int, float>>& result) {
    if (max_checks > 0) {
      smallest_at_most(lbs, rows, limit, static_cast<size_t>(max_checks), cand, avx2);
      capped(q, margin, cand, result);
      return;
    }
    float bar = limit;
    const auto next = avx2 ? next_at_most_avx2 : next_at_most;
    for (size_t r = next(lbs, 0, rows, bar); r < rows; r = next(lbs, r + 1, rows, bar))
      consider(q, r, margin, bar, result);
  }
};

// The first pass over every row's bound: the kk smallest (value, then
// row); for kk = 1 the smallest, the lowest row among equal ones (`min`:
// the smallest bound when the bounds' kernel gave it, else null).
void smallest_bounds(const float* lbs, size_t rows, size_t kk, const float* min,
                     std::vector<std::pair<float, int>>& cand) {
  if (kk == 1) {
    size_t arg = rows;
    if (min) arg = first_equal_avx2(lbs, rows, *min);
    if (arg == rows) arg = first_argmin(lbs, rows);  // no minimum given, or none equals it (NaN)
    cand.emplace_back(lbs[arg], static_cast<int>(arg));
    return;
  }
  for (size_t r = 0; r < rows; ++r)
    if (cand.size() < kk || lbs[r] < cand.back().first) keep_smallest(cand, kk, {lbs[r], static_cast<int>(r)});
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
  std::vector<float> zn;
  const RowMat Zq = impl_->project(queries, n, zn);  // n x proj_dim
  return bounds_projected(Zq.data(), zn.data(), n, lbs, mins);
}

bool DescriptorIndex::bounds_projected(const float* zq, const float* zn, int n, float* lbs, float* mins) const {
  const Impl& m = *impl_;
  const Eigen::Map<const RowMat> Zq(zq, n, m.proj_dim);
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
                               std::all_of(zn, zn + n, [](float v) { return v < 1e30f; });
    long_bounds_avx2(Zq.data(), zn, n, m.proj_dim, m.proj_t.data(), m.proj_sq.data(), m.rows, lbs,
                     mins && finite_bounds ? mins : nullptr);
    return mins && finite_bounds;
  } else if (m.dim > kShortRows) {
    long_bounds(Zq.data(), zn, n, m.proj_dim, m.proj_t.data(), m.proj_sq.data(), m.rows, lbs);
  } else if (m.avx2_bounds && m.proj_dim == kProjDimShort && cpu_has_fma()) {
    std::vector<float> own(mins ? 0 : static_cast<size_t>(n));
    short_bounds_fma(Zq.data(), zn, n, m.proj_t.data(), m.proj_sq.data(), m.rows, lbs,
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
  // Long rows with clusters: each query's bounds only where they can matter
  // (match_clusters.h), from the block's projections, where every squared
  // norm is under 1e30 (no sum overflows). Otherwise every row's bound.
  std::vector<float> zn;
  RowMat Zq;
  bool pruned = m.use_clusters;
  if (pruned) {
    Zq = m.project(queries, n, zn);
    pruned = std::all_of(zn.begin(), zn.end(), [](float v) { return v < 1e30f; });
  }
  // Short rows: the bounds of four queries at a time (4 x rows floats stay in
  // the L2 cache; the warehouse's 17,526 rows for a block of 32 took 2.2 MB).
  // Long rows: the whole block at once, each tile of the rows' projections
  // read for every query of the block (groups of four took 15% longer).
  // With clusters, the queries go by them until one (judged every
  // kDenseProbe) is likely to need more than kDenseShare of the blocks
  // (queries far from every row, whose limit is the threshold: nearly every
  // bound is under it); that one and the block's rest then take every row's
  // bound, in one group (the same answers either way).
  const int group = m.dim > kShortRows ? n : 4;
  std::unique_ptr<float[]> all;
  std::vector<float> mins(static_cast<size_t>(group));
  bool have_mins = false;
  int dense_from = pruned ? n : 0;  // queries from this one on: every row's bound
  const auto dist = m.avx2_bounds ? sq_dist_avx2 : sq_dist;  // the same bits
  std::vector<std::pair<float, int>> cand, within;
  ClusterQuery cq;
  cq.avx2 = m.avx2_bounds;
  SecondPass pass{m.data.data(), dim, kk, max_sq_dist, dist, {}, {}};
  for (int i = 0; i < n; ++i) {
    out[i].clear();
    const float* q = queries + static_cast<size_t>(i) * dim;
    float qn = 0;
    for (size_t j = 0; j < dim; ++j) qn += q[j] * q[j];
    // Rounding margin of the product form and of the float basis: generous.
    const float margin = 1e-4f * (qn + m.max_sq_norm) + 1e-30f;
    if (pruned) {
      cq.zq = Zq.row(i).data();
      cq.zn = zn[static_cast<size_t>(i)];
      cq.margin = margin;
      cluster_distances(m.clusters, cq);
      if (i % kDenseProbe == 0 && m.dense_better(cq, q, max_sq_dist)) pruned = false, dense_from = i;
    }
    if (!pruned && (i - dense_from) % group == 0) {
      if (!all) all.reset(new float[static_cast<size_t>(group) * m.rows]);
      const int count = std::min(group, n - i);
      have_mins = Zq.rows() > 0  // the block's projections are at hand (clusters)
                      ? bounds_projected(Zq.row(i).data(), zn.data() + i, count, all.get(), mins.data())
                      : bounds(q, count, all.get(), mins.data());
    }
    // First pass: the kk smallest bounds (value, then row); their exact
    // distances cap the k-th best (tau0), so only rows with a bound up to
    // tau0 remain candidates.
    const int slot = pruned ? 0 : (i - dense_from) % group;
    const float* lbs = pruned ? nullptr : all.get() + static_cast<size_t>(slot) * m.rows;
    cand.clear();
    if (pruned) cluster_smallest(m.clusters, cq, kk, cand);
    else smallest_bounds(lbs, m.rows, kk, have_mins ? &mins[static_cast<size_t>(slot)] : nullptr, cand);
    const float limit = std::min(pass.largest_distance(q, cand), max_sq_dist) + margin;
    if (pruned) {  // every row with a bound up to the limit, the others' bounds are above it
      cluster_within(m.clusters, cq, limit, within);
      pass.over_listed(q, margin, limit, max_checks, within, out[i]);
    } else {
      pass.over_bounds(q, margin, limit, max_checks, lbs, m.rows, m.avx2_bounds, cand, out[i]);
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
