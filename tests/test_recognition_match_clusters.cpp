// The descriptor index's row clusters (match_clusters.h): the pruned bounds
// are long_bounds' bits for every row they compute, they find exactly the
// rows a full computation finds (the kk smallest, every row up to a limit,
// ties and limits equal to a bound included), and knn_block's answers with
// and without the clusters are the same, bit for bit, for SHOT-sized rows,
// exact and capped, on the plain and the AVX2 kernels.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/cpu.h"
#include "core/random.h"
#include "recognition/local/internal.h"
#include "recognition/local/match_clusters.h"
#include "recognition/local/match_kernels.h"

namespace {

constexpr int kAxes = pb::local::kProjDim;

// Projections around a few centres (as SHOT's rows are), some rows repeated
// exactly (equal bounds: the lower row first).
struct Projected {
  size_t rows = 0;
  std::vector<float> proj, psq, zt;  // row-major, squared norms, axis by axis
};

Projected projected_rows(size_t rows, int centres, pb::Rng& rng) {
  std::vector<float> c(static_cast<size_t>(centres) * kAxes);
  for (float& v : c) v = static_cast<float>(rng.normal(0, 0.4));
  Projected p;
  p.rows = rows;
  for (size_t r = 0; r < rows; ++r) {
    if (r > 10 && rng.uniform() < 0.02) {  // a copy of an earlier row
      const size_t src = static_cast<size_t>(rng.uniform_int(0, static_cast<int>(r) - 1));
      for (int a = 0; a < kAxes; ++a) p.proj.push_back(p.proj[src * kAxes + static_cast<size_t>(a)]);
      continue;
    }
    const int k = rng.uniform_int(0, centres - 1);
    for (int a = 0; a < kAxes; ++a)
      p.proj.push_back(c[static_cast<size_t>(k) * kAxes + static_cast<size_t>(a)] +
                       static_cast<float>(rng.normal(0, 0.1)));
  }
  p.psq.assign(rows, 0.f);
  p.zt.assign(rows * kAxes, 0.f);
  for (size_t r = 0; r < rows; ++r)
    for (int a = 0; a < kAxes; ++a) {
      const float v = p.proj[r * kAxes + static_cast<size_t>(a)];
      p.psq[r] += v * v;
      p.zt[static_cast<size_t>(a) * rows + r] = v;
    }
  return p;
}

std::vector<float> query_near(const Projected& p, double sigma, pb::Rng& rng) {
  const size_t src = static_cast<size_t>(rng.uniform_int(0, static_cast<int>(p.rows) - 1));
  std::vector<float> q(kAxes);
  for (int a = 0; a < kAxes; ++a)
    q[static_cast<size_t>(a)] = p.proj[src * kAxes + static_cast<size_t>(a)] + static_cast<float>(rng.normal(0, sigma));
  return q;
}

TEST(RowClusters, PrunedBoundsFindWhatEveryRowsBoundFinds) {
  pb::Rng rng(3);
  for (const size_t rows : {size_t{1}, size_t{150}, size_t{1029}, size_t{5000}}) {
    const Projected p = projected_rows(rows, 30, rng);
    const pb::local::RowClusters c = pb::local::cluster_rows(p.proj.data(), p.psq.data(), rows, kAxes);
    // Every row has one position, in its cluster's run.
    std::vector<int> seen(rows, 0);
    for (size_t i = 0; i < c.count(); ++i)
      for (size_t q = c.begin[i]; q < c.end[i]; ++q) ++seen[static_cast<size_t>(c.row[q])];
    ASSERT_EQ(std::count(seen.begin(), seen.end(), 1), static_cast<long>(rows));
    for (int t = 0; t < 40; ++t) {
      std::vector<float> zq = query_near(p, t % 2 == 0 ? 0.0 : 0.3, rng);
      float zn = 0;
      for (const float v : zq) zn += v * v;
      std::vector<float> full(rows);  // long_bounds over every row
      pb::local::long_bounds(zq.data(), &zn, 1, kAxes, p.zt.data(), p.psq.data(), rows, full.data());
      for (const bool avx2 : {false, true}) {
        if (avx2 && !pb::cpu_has_avx2()) continue;
        pb::local::ClusterQuery q;
        q.zq = zq.data();
        q.zn = zn;
        q.margin = 1e-4f * (zn + *std::max_element(p.psq.begin(), p.psq.end()));
        q.avx2 = avx2;
        pb::local::cluster_distances(c, q);
        for (const size_t kk : {size_t{1}, size_t{3}, size_t{10}}) {
          std::vector<std::pair<float, int>> want, got;
          for (size_t r = 0; r < rows; ++r) want.emplace_back(full[r], static_cast<int>(r));
          std::sort(want.begin(), want.end());
          want.resize(std::min(kk, rows));
          pb::local::cluster_smallest(c, q, kk, got);
          ASSERT_EQ(got.size(), want.size());
          for (size_t e = 0; e < want.size(); ++e) {  // the same rows, the same bits
            ASSERT_EQ(got[e].second, want[e].second) << "rows " << rows << " query " << t << " kk " << kk;
            ASSERT_EQ(std::memcmp(&got[e].first, &want[e].first, sizeof(float)), 0);
          }
        }
        // Limits: a bound itself (a row exactly at the limit is in), between
        // bounds, and infinite.
        std::vector<float> sorted = full;
        std::sort(sorted.begin(), sorted.end());
        for (const float limit : {sorted[0], sorted[rows / 50], sorted[rows / 5], sorted[rows - 1],
                                  std::numeric_limits<float>::infinity()}) {
          std::vector<std::pair<float, int>> want, got;
          for (size_t r = 0; r < rows; ++r)
            if (full[r] <= limit) want.emplace_back(full[r], static_cast<int>(r));
          pb::local::cluster_within(c, q, limit, got);
          std::sort(got.begin(), got.end());  // in no set order; want: by row, so by (bound, row) too
          std::sort(want.begin(), want.end());
          ASSERT_EQ(got.size(), want.size()) << "rows " << rows << " query " << t << " limit " << limit;
          for (size_t e = 0; e < want.size(); ++e) {
            ASSERT_EQ(got[e].second, want[e].second);
            ASSERT_EQ(std::memcmp(&got[e].first, &want[e].first, sizeof(float)), 0);
          }
        }
      }
    }
  }
}

// Unit-norm non-negative rows of 352 values around a few centres, with exact
// duplicates, as SHOT's.
std::vector<float> shot_rows(int rows, pb::Rng& rng) {
  constexpr int kDim = 352;
  std::vector<std::vector<double>> centres(50, std::vector<double>(kDim));
  for (auto& c : centres)
    for (auto& x : c) x = rng.uniform() < 0.3 ? rng.uniform() : 0.0;
  std::vector<float> out;
  for (int r = 0; r < rows; ++r) {
    if (r > 10 && rng.uniform() < 0.02) {
      const int src = rng.uniform_int(0, r - 1);
      out.insert(out.end(), out.begin() + src * kDim, out.begin() + (src + 1) * kDim);
      continue;
    }
    const auto& c = centres[static_cast<size_t>(rng.uniform_int(0, 49))];
    std::vector<double> v(kDim);
    double n = 0;
    for (int j = 0; j < kDim; ++j) {
      v[static_cast<size_t>(j)] = std::max(0.0, c[static_cast<size_t>(j)] + rng.normal(0, 0.05));
      n += v[static_cast<size_t>(j)] * v[static_cast<size_t>(j)];
    }
    for (int j = 0; j < kDim; ++j) out.push_back(static_cast<float>(v[static_cast<size_t>(j)] / std::sqrt(n)));
  }
  return out;
}

TEST(RowClusters, SearchGivesTheSameAnswersWithAndWithoutClusters) {
  constexpr int kDim = 352;
  pb::Rng rng(19);
  const std::vector<float> data = shot_rows(5000, rng);  // clusters from 4096 rows on
  const int rows = static_cast<int>(data.size() / kDim);
  pb::local::DescriptorIndex index;
  index.build(data, kDim);
  ASSERT_TRUE(index.has_clusters());
  std::vector<float> queries;  // exact copies (ties among duplicates), noisy copies, midpoints
  for (int q = 0; q < 240; ++q) {
    const int a = rng.uniform_int(0, rows - 1), b = rng.uniform_int(0, rows - 1);
    for (int j = 0; j < kDim; ++j) {
      const float x = data[static_cast<size_t>(a) * kDim + j], y = data[static_cast<size_t>(b) * kDim + j];
      queries.push_back(q % 3 == 0 ? x : q % 3 == 1 ? std::max(0.f, x + static_cast<float>(rng.normal(0, 0.03)))
                                                    : 0.5f * (x + y));
    }
  }
  const int n = static_cast<int>(queries.size() / kDim);
  using Result = std::vector<std::vector<std::pair<int, float>>>;
  size_t found = 0;
  // Blocks of 32 queries, as the pipeline's; with clusters throughout (a
  // share over 1), every row's bound from the first query (0), and as by
  // default.
  const auto search = [&](int k, float thr, int checks, Result& out) {
    for (int first = 0; first < n; first += 32)
      index.knn_block(queries.data() + static_cast<size_t>(first) * kDim, std::min(32, n - first), k, thr,
                      out.data() + first, checks);
  };
  for (const bool avx2 : {false, true}) {
    index.set_avx2_bounds(avx2);
    for (const int k : {1, 3})
      for (const float thr : {0.05f, 0.5f, 4.f})
        for (const int checks : {0, 64, 16}) {
          Result without(static_cast<size_t>(n));
          index.set_clusters(false);
          search(k, thr, checks, without);
          for (const double share : {2.0, 0.0, 0.4}) {
            Result with(static_cast<size_t>(n));
            index.set_clusters(true);
            index.set_dense_share(share);
            search(k, thr, checks, with);
            for (int i = 0; i < n; ++i) {
              ASSERT_EQ(with[static_cast<size_t>(i)], without[static_cast<size_t>(i)])
                  << "query " << i << " k " << k << " threshold " << thr << " checks " << checks << " avx2 " << avx2
                  << " share " << share;
              found += with[static_cast<size_t>(i)].size();
            }
          }
        }
  }
  EXPECT_GT(found, 6000u);  // the comparison is not between empty answers
  // Blocks of 16 whose first eight queries are rows' exact copies (a small
  // limit: the clusters) and whose last eight are far from every row under a
  // threshold of 4 (the limit spans most rows: every row's bound from the
  // ninth query on, where the search next judges), against the search
  // without clusters.
  std::vector<float> mixed;
  pb::Rng far_rng(5);
  const std::vector<float> far = shot_rows(400, far_rng);  // other centres
  for (int b = 0; b < 10; ++b) {
    for (int j = 0; j < 8; ++j) {
      const int src = rng.uniform_int(0, rows - 1);
      mixed.insert(mixed.end(), data.begin() + src * kDim, data.begin() + (src + 1) * kDim);
    }
    mixed.insert(mixed.end(), far.begin() + (8 * b) * kDim, far.begin() + (8 * b + 8) * kDim);
  }
  index.set_dense_share(0.4);
  for (const int checks : {0, 64}) {
    Result with(160), without(160);
    for (const bool clusters : {true, false}) {
      index.set_clusters(clusters);
      for (int first = 0; first < 160; first += 16)
        index.knn_block(mixed.data() + static_cast<size_t>(first) * kDim, 16, 1, 4.f,
                        (clusters ? with : without).data() + first, checks);
    }
    EXPECT_EQ(with, without) << "checks " << checks;
  }
  index.set_clusters(true);
  // A cap of every row: the capped search gives the exact search's answers.
  for (const int k : {1, 3}) {
    Result exact(static_cast<size_t>(n)), all(static_cast<size_t>(n));
    index.knn_block(queries.data(), n, k, 4.f, exact.data());
    index.knn_block(queries.data(), n, k, 4.f, all.data(), rows);
    EXPECT_EQ(all, exact) << "k " << k;
  }
}

}  // namespace
