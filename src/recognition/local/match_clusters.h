// The descriptor index's row clusters (match.cpp): the rows' projections on
// the principal axes grouped around k-means centroids, so that a query's
// bounds are computed only for the rows that can matter. By the triangle
// inequality the projected distance of a query q to a row r of the cluster
// with centroid c is at least |d(q, c) - d(r, c)|; rows are kept in order of
// d(r, c) within each cluster, so the rows that can have a bound up to some X
// are one run of positions per cluster, found by counting the sorted
// distances below its ends. Skipping the
// others changes no answer: the bounds computed are long_bounds' bits (the
// same float operations, match_kernels.h), and a row is skipped only where
// its bound is provably above X, with the rounding margin the search already
// allows for. The clustering itself (its centroids and iterations) decides
// only how much is skipped, never what is found.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace pb::local {

struct RowClusters {
  int pd = 0;                     // axes of the projections
  std::vector<float> centroid_t;  // pd x cstride: the centroids axis by axis (zero padding)
  size_t cstride = 0;             // values per axis in centroid_t (clusters rounded up to eight)
  std::vector<double> radius;     // per cluster: the largest d(r, c) of its rows
  std::vector<uint32_t> begin;    // per cluster: its first position (a multiple of eight)
  std::vector<uint32_t> end;      // per cluster: one past its last row's position
  std::vector<int> row;           // position -> row of the index (-1: padding up to the next eight)
  std::vector<float> rdist;       // position -> d(r, c), ascending within each cluster (padding: infinity)
  std::vector<float> blocks;      // per eight positions: pd x 8 projections (axis, then position)
  std::vector<float> psq;         // position -> the projection's squared norm (padding: 0)
  size_t count() const { return radius.size(); }
  size_t block_count() const { return row.size() / 8; }
};

// The clusters of `rows` projected rows (proj: rows x pd, row-major; psq:
// their squared norms, as the bounds use them): about one cluster per 100
// rows, k-means from evenly spaced rows for a fixed number of iterations
// (deterministic); clusters left empty are dropped.
RowClusters cluster_rows(const float* proj, const float* psq, size_t rows, int pd);

// One query's pruned bounds: its projection zq (pd values) and squared norm
// zn, and `margin`, at least the rounding error of any bound (knn_block's).
struct ClusterQuery {
  const float* zq = nullptr;
  float zn = 0;
  float margin = 0;
  bool avx2 = false;      // with the AVX2 kernels (the same bounds)
  std::vector<float> cd;  // the distances to the centroids (cluster_distances)
};

// The query's distances to the centroids, into q.cd: first, before the two
// searches below.
void cluster_distances(const RowClusters& c, ClusterQuery& q);

// The smallest (bound, row) of the nearest centroid's cluster ((inf, -1)
// without clusters): a row near the query whose exact distance tells the
// limit the searches are likely to have.
std::pair<float, int> cluster_near_best(const RowClusters& c, const ClusterQuery& q);

// How many blocks of eight bounds the rows that can have a bound up to X
// span (cluster_within's work for that limit; nothing is computed).
size_t cluster_reach(const RowClusters& c, const ClusterQuery& q, float X);

// The kk smallest (bound, row) pairs over every row (value, then row), in
// ascending order: what knn_block's first pass takes from the full bounds.
void cluster_smallest(const RowClusters& c, const ClusterQuery& q, size_t kk,
                      std::vector<std::pair<float, int>>& out);

// Every (bound, row) with bound <= limit (NaN never), in no set order.
void cluster_within(const RowClusters& c, const ClusterQuery& q, float limit,
                    std::vector<std::pair<float, int>>& out);

}  // namespace pb::local
