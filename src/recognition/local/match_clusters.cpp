// The descriptor index's row clusters and its pruned bounds
// (match_clusters.h).
#include "recognition/local/match_clusters.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "recognition/local/match_kernels.h"

namespace pb::local {

namespace {

constexpr size_t kRowsPerCluster = 100;  // about this many rows per cluster
constexpr int kIterations = 5;            // k-means iterations (then the final assignment)
using RowMatF = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Each row's nearest centroid (squared distances from the product form in
// float: only the clustering's quality depends on them).
std::vector<int> assign(const Eigen::Map<const RowMatF>& Z, const std::vector<double>& centroid, size_t k, int pd) {
  RowMatF C(static_cast<Eigen::Index>(k), pd);
  for (size_t c = 0; c < k; ++c)
    for (int a = 0; a < pd; ++a) C(static_cast<Eigen::Index>(c), a) = static_cast<float>(centroid[c * pd + a]);
  const Eigen::VectorXf cn = C.rowwise().squaredNorm();
  const RowMatF D = Z * C.transpose();
  std::vector<int> out(static_cast<size_t>(Z.rows()));
  for (Eigen::Index r = 0; r < Z.rows(); ++r) {
    Eigen::Index best = 0;
    (cn.transpose() - 2.f * D.row(r)).minCoeff(&best);
    out[static_cast<size_t>(r)] = static_cast<int>(best);
  }
  return out;
}

double distance(const float* z, const double* c, int pd) {
  double s = 0;
  for (int a = 0; a < pd; ++a) {
    const double t = static_cast<double>(z[a]) - c[a];
    s += t * t;
  }
  return std::sqrt(s);
}

// Per thread: the blocks of eight positions to bound (ids, n of them in
// use), the lanes of each that are in a run (bit l: position 8 id + l), and
// the bounds of every block this query has computed (stamp == token: cache,
// eight values per block), so that the second search reuses the first's.
struct Scratch {
  std::vector<uint32_t> ids, todo;
  std::vector<uint8_t> lanes;
  size_t n = 0;
  std::vector<uint32_t> stamp;
  std::vector<float> cache, fresh;
  uint32_t token = 0;
  void start_query(const RowClusters& c) {
    const size_t blocks = c.row.size() / 8;
    if (stamp.size() < blocks) {
      stamp.resize(blocks, 0);
      cache.resize(8 * blocks);
    }
    if (++token == 0) {  // wrapped: no stamp may equal a later token
      std::fill(stamp.begin(), stamp.end(), 0);
      token = 1;
    }
  }
  void clear(const RowClusters& c) {
    const size_t most = c.row.size() / 8 + c.count();  // a cluster's run adds at most one block beyond its own
    if (ids.size() < most) {
      ids.resize(most);
      todo.resize(most);
      lanes.resize(most);
      fresh.resize(8 * most);
    }
    n = 0;
  }
};
thread_local Scratch scratch;

// The squared distances of a query to the centroids, eight centroids at a
// time, in float (their rounding, at most a few parts in a million, is
// within add_runs' slack).
void centroid_sq(const float* zq, int pd, const float* ct, size_t cstride, float* out) {
  for (size_t c = 0; c < cstride; ++c) out[c] = 0.f;
  for (int a = 0; a < pd; ++a)
    for (size_t c = 0; c < cstride; ++c) {
      const float t = zq[a] - ct[static_cast<size_t>(a) * cstride + c];
      out[c] += t * t;
    }
}
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2"))) void centroid_sq_avx2(const float* zq, int pd, const float* ct, size_t cstride,
                                                      float* out) {
  for (size_t c = 0; c < cstride; c += 8) {
    __m256 acc = _mm256_setzero_ps();
    for (int a = 0; a < pd; ++a) {
      const __m256 t = _mm256_sub_ps(_mm256_set1_ps(zq[a]), _mm256_loadu_ps(ct + static_cast<size_t>(a) * cstride + c));
      acc = _mm256_add_ps(acc, _mm256_mul_ps(t, t));
    }
    _mm256_storeu_ps(out + c, acc);
  }
}
#else
void centroid_sq_avx2(const float* zq, int pd, const float* ct, size_t cstride, float* out) {
  centroid_sq(zq, pd, ct, cstride, out);
}
#endif

// The number of values of v[0..n) (n a multiple of eight) below x, or at
// most x: where v ascends, the first position at or above x, or above x.
size_t count_below(const float* v, size_t n, float x, bool or_equal) {
  size_t k = 0;
  for (size_t p = 0; p < n; ++p) k += or_equal ? v[p] <= x : v[p] < x;
  return k;
}
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2,popcnt"))) size_t count_below_avx2(const float* v, size_t n, float x, bool or_equal) {
  const __m256 x8 = _mm256_set1_ps(x);
  size_t k = 0;
  for (size_t p = 0; p < n; p += 8) {
    const __m256 c = or_equal ? _mm256_cmp_ps(_mm256_loadu_ps(v + p), x8, _CMP_LE_OQ)
                              : _mm256_cmp_ps(_mm256_loadu_ps(v + p), x8, _CMP_LT_OQ);
    k += static_cast<size_t>(__builtin_popcount(static_cast<unsigned>(_mm256_movemask_ps(c))));
  }
  return k;
}
#else
size_t count_below_avx2(const float* v, size_t n, float x, bool or_equal) { return count_below(v, n, x, or_equal); }
#endif

// The lanes l of v[0..8) with v[l] <= x (bit l).
unsigned lanes_at_most(const float* v, float x) {
  unsigned m = 0;
  for (unsigned l = 0; l < 8; ++l) m |= static_cast<unsigned>(v[l] <= x) << l;
  return m;
}
#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2"))) unsigned lanes_at_most_avx2(const float* v, float x) {
  return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(v), _mm256_set1_ps(x), _CMP_LE_OQ)));
}
#else
unsigned lanes_at_most_avx2(const float* v, float x) { return lanes_at_most(v, x); }
#endif

// Appends the blocks covering the positions [lo, hi), with their lanes.
void add_positions(size_t lo, size_t hi, Scratch& s) {
  for (size_t b = lo / 8; b * 8 < hi; ++b) {
    const size_t l0 = std::max(lo, 8 * b) - 8 * b, l1 = std::min(hi, 8 * b + 8) - 8 * b;
    s.ids[s.n] = static_cast<uint32_t>(b);
    s.lanes[s.n++] = static_cast<uint8_t>(((1u << l1) - 1u) & ~((1u << l0) - 1u));
  }
}

// Appends, for every cluster but `skip`, the blocks covering the run of
// positions whose rows can have a bound up to X (every row where X is
// infinite): a row r outside it has |d(q, c) - d(r, c)| > reach, so its
// exact projected distance is above sqrt(X + margin) (reach's slack covers
// the rounding of the float distances, to the centroids and of the rows),
// and its bound, within `margin` of that distance squared, above X.
void add_runs(const RowClusters& c, const ClusterQuery& q, double X, size_t skip, Scratch& s) {
  const bool all = !std::isfinite(X);
  const double root = all ? 0.0 : std::sqrt(X + static_cast<double>(q.margin));
  const auto count = q.avx2 ? count_below_avx2 : count_below;
  for (size_t i = 0; i < c.count(); ++i) {
    if (i == skip) continue;
    size_t lo = c.begin[i], hi = c.end[i];
    if (!all) {
      const double cd = q.cd[i];
      const double reach = root * (1 + 1e-5) + 1e-5 * (cd + c.radius[i]) + 1e-30;
      if (cd - c.radius[i] > reach) continue;
      const size_t n = (hi - lo + 7) / 8 * 8;  // the padding's distances are infinite
      const float* v = c.rdist.data() + lo;
      hi = lo + count(v, n, static_cast<float>(cd + reach), true);
      lo += count(v, n, static_cast<float>(cd - reach), false);
    }
    add_positions(lo, hi, s);
  }
}

// The bounds of the listed blocks into the cache: those the query has not
// computed yet.
void compute(const RowClusters& c, const ClusterQuery& q, Scratch& s) {
  size_t m = 0;
  for (size_t i = 0; i < s.n; ++i)
    if (s.stamp[s.ids[i]] != s.token) s.todo[m++] = s.ids[i];
  const auto kernel = q.avx2 ? long_bounds_blocks_avx2 : long_bounds_blocks;
  kernel(q.zq, q.zn, c.pd, c.blocks.data(), c.psq.data(), s.todo.data(), m, s.fresh.data());
  for (size_t j = 0; j < m; ++j) {
    std::memcpy(s.cache.data() + 8 * static_cast<size_t>(s.todo[j]), s.fresh.data() + 8 * j, 8 * sizeof(float));
    s.stamp[s.todo[j]] = s.token;
  }
}

size_t nearest_cluster(const RowClusters& c, const ClusterQuery& q) {
  return static_cast<size_t>(std::min_element(q.cd.begin(), q.cd.begin() + static_cast<long>(c.count())) -
                             q.cd.begin());
}

// Lloyd's iterations (kIterations) from k evenly spaced rows: the
// centroids (k x pd) and each row's cluster (member).
std::vector<double> k_means(const float* proj, size_t rows, int pd, size_t k, std::vector<int>& member) {
  const Eigen::Map<const RowMatF> Z(proj, static_cast<Eigen::Index>(rows), pd);
  std::vector<double> centroid(k * pd);
  for (size_t c = 0; c < k; ++c)  // evenly spaced rows
    for (int a = 0; a < pd; ++a) centroid[c * pd + a] = proj[(c * rows / k) * pd + a];
  member = assign(Z, centroid, k, pd);
  for (int it = 0; it < kIterations; ++it) {
    std::vector<double> sum(k * pd, 0.0);
    std::vector<size_t> n(k, 0);
    for (size_t r = 0; r < rows; ++r) {
      const size_t c = static_cast<size_t>(member[r]);
      ++n[c];
      for (int a = 0; a < pd; ++a) sum[c * pd + a] += proj[r * pd + a];
    }
    for (size_t c = 0; c < k; ++c)  // an empty cluster keeps its centroid
      if (n[c] > 0)
        for (int a = 0; a < pd; ++a) centroid[c * pd + a] = sum[c * pd + a] / static_cast<double>(n[c]);
    member = assign(Z, centroid, k, pd);
  }
  return centroid;
}

// Clusters left empty are dropped (a nearest centroid then always has
// rows), the others renumbered in order; the number kept.
size_t drop_empty(std::vector<double>& centroid, std::vector<int>& member, size_t k, int pd) {
  std::vector<int> kept(k, -1);
  std::vector<char> used(k, 0);
  for (const int c : member) used[static_cast<size_t>(c)] = 1;
  size_t m = 0;
  for (size_t c = 0; c < k; ++c)
    if (used[c]) {
      kept[c] = static_cast<int>(m);
      if (m != c)
        std::copy_n(centroid.begin() + static_cast<long>(c * pd), pd, centroid.begin() + static_cast<long>(m * pd));
      ++m;
    }
  for (int& c : member) c = kept[static_cast<size_t>(c)];
  centroid.resize(m * pd);
  return m;
}

// The rows in their positions: cluster by cluster, each in order of
// d(r, c) (then row), each cluster's run padded to whole blocks of eight;
// with their distances (rounded up), projections and squared norms.
void place_rows(const float* proj, const float* psq, size_t rows, int pd, size_t k, const std::vector<double>& centroid,
                const std::vector<int>& member, RowClusters& out) {
  std::vector<std::pair<double, int>> order(rows);
  std::vector<size_t> n(k, 0);
  for (size_t r = 0; r < rows; ++r) {
    const size_t c = static_cast<size_t>(member[r]);
    order[r] = {distance(proj + r * pd, centroid.data() + c * pd, pd), static_cast<int>(r)};
    ++n[c];
  }
  out.radius.assign(k, 0.0);
  out.begin.assign(k, 0);
  out.end.assign(k, 0);
  for (size_t c = 0, p = 0; c < k; ++c) {
    out.begin[c] = static_cast<uint32_t>(p);
    out.end[c] = static_cast<uint32_t>(p + n[c]);
    p += (n[c] + 7) / 8 * 8;
  }
  std::sort(order.begin(), order.end(), [&](const auto& x, const auto& y) {
    const int cx = member[static_cast<size_t>(x.second)], cy = member[static_cast<size_t>(y.second)];
    return cx != cy ? cx < cy : x < y;
  });
  const size_t positions = k == 0 ? 0 : (out.end[k - 1] + 7) / 8 * 8;
  out.row.assign(positions, -1);
  out.rdist.assign(positions, std::numeric_limits<float>::infinity());
  out.blocks.assign(positions * pd, 0.f);
  out.psq.assign(positions, 0.f);
  std::vector<size_t> next(out.begin.begin(), out.begin.end());
  for (const auto& [d, r] : order) {
    const size_t c = static_cast<size_t>(member[static_cast<size_t>(r)]);
    const size_t p = next[c]++;
    out.row[p] = r;
    // Rounded up to the next float: never below the double distance.
    out.rdist[p] = std::nextafter(static_cast<float>(d), std::numeric_limits<float>::infinity());
    out.radius[c] = std::max(out.radius[c], static_cast<double>(out.rdist[p]));
    for (int a = 0; a < pd; ++a) out.blocks[(p / 8 * pd + a) * 8 + p % 8] = proj[static_cast<size_t>(r) * pd + a];
    out.psq[p] = psq[r];
  }
}

}  // namespace

RowClusters cluster_rows(const float* proj, const float* psq, size_t rows, int pd) {
  RowClusters out;
  out.pd = pd;
  if (rows == 0 || pd <= 0) return out;
  const size_t tried = std::max<size_t>(1, rows / kRowsPerCluster);
  std::vector<int> member;
  std::vector<double> centroid = k_means(proj, rows, pd, tried, member);
  const size_t k = drop_empty(centroid, member, tried, pd);
  // The centroids as the queries' distances read them (float, axis by axis);
  // each row's distance to its centroid in double from those floats.
  out.cstride = (k + 7) / 8 * 8;
  out.centroid_t.assign(static_cast<size_t>(pd) * out.cstride, 0.f);
  for (size_t c = 0; c < k; ++c)
    for (int a = 0; a < pd; ++a) {
      const float v = static_cast<float>(centroid[c * pd + a]);
      out.centroid_t[static_cast<size_t>(a) * out.cstride + c] = v;
      centroid[c * pd + a] = v;
    }
  place_rows(proj, psq, rows, pd, k, centroid, member, out);
  return out;
}

void cluster_distances(const RowClusters& c, ClusterQuery& q) {
  q.cd.resize(c.cstride);
  (q.avx2 ? centroid_sq_avx2 : centroid_sq)(q.zq, c.pd, c.centroid_t.data(), c.cstride, q.cd.data());
  for (float& d : q.cd) d = std::sqrt(d);
  scratch.start_query(c);
}

std::pair<float, int> cluster_near_best(const RowClusters& c, const ClusterQuery& q) {
  std::pair<float, int> best(std::numeric_limits<float>::infinity(), -1);
  if (c.count() == 0) return best;
  Scratch& s = scratch;
  const size_t near = nearest_cluster(c, q);
  s.clear(c);
  add_positions(c.begin[near], c.end[near], s);
  compute(c, q, s);
  for (size_t i = 0; i < s.n; ++i)
    for (unsigned m = s.lanes[i]; m != 0; m &= m - 1) {
      const unsigned l = static_cast<unsigned>(__builtin_ctz(m));
      const std::pair<float, int> e(s.cache[8 * static_cast<size_t>(s.ids[i]) + l], c.row[8 * s.ids[i] + l]);
      if (e < best || best.second < 0) best = e;
    }
  return best;
}

size_t cluster_reach(const RowClusters& c, const ClusterQuery& q, float X) {
  Scratch& s = scratch;
  s.clear(c);
  add_runs(c, q, X, c.count(), s);
  return s.n;
}

void cluster_smallest(const RowClusters& c, const ClusterQuery& q, size_t kk,
                      std::vector<std::pair<float, int>>& out) {
  out.clear();
  if (kk == 0 || c.count() == 0) return;
  Scratch& s = scratch;
  const auto offer = [&] {
    for (size_t i = 0; i < s.n; ++i)
      for (unsigned m = s.lanes[i]; m != 0; m &= m - 1) {
        const unsigned l = static_cast<unsigned>(__builtin_ctz(m));
        const float v = s.cache[8 * static_cast<size_t>(s.ids[i]) + l];
        if (out.size() == kk && v > out.back().first) continue;  // most lanes: no row needed
        keep_smallest(out, kk, {v, c.row[8 * s.ids[i] + l]});
      }
  };
  // The nearest centroid's cluster in full, then every other one's rows that
  // can have a bound up to the kk-th smallest so far (any X at least the
  // final one skips only rows that are not among the kk smallest).
  const size_t near = nearest_cluster(c, q);
  s.clear(c);
  add_positions(c.begin[near], c.end[near], s);
  compute(c, q, s);
  offer();
  const double X = out.size() == kk ? out.back().first : std::numeric_limits<double>::infinity();
  s.clear(c);
  add_runs(c, q, X, near, s);
  compute(c, q, s);
  offer();
}

void cluster_within(const RowClusters& c, const ClusterQuery& q, float limit,
                    std::vector<std::pair<float, int>>& out) {
  out.clear();
  if (c.count() == 0) return;
  Scratch& s = scratch;
  s.clear(c);
  add_runs(c, q, limit, c.count(), s);
  compute(c, q, s);
  const auto at_most = q.avx2 ? lanes_at_most_avx2 : lanes_at_most;
  for (size_t i = 0; i < s.n; ++i) {
    const float* v = s.cache.data() + 8 * static_cast<size_t>(s.ids[i]);
    for (unsigned m = at_most(v, limit) & s.lanes[i]; m != 0; m &= m - 1) {
      const unsigned l = static_cast<unsigned>(__builtin_ctz(m));
      out.emplace_back(v[l], c.row[8 * s.ids[i] + l]);
    }
  }
}

}  // namespace pb::local
