// The descriptor index's blocked search (a projected lower bound, then exact
// distances) against its exact linear scan (knn, one query at a time), on
// SHOT-sized descriptors (clustered rows, exact duplicate rows (ties), noisy
// copies of rows and unrelated queries) and FPFH-sized ones, for several k
// and thresholds. The results must be equal bit for bit: rows, order and
// distances. The approximate search (max_checks) against the same scan:
// exact when the cap cannot bind, a recall it must reach when it does; its
// candidate selection against listing every candidate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "core/cpu.h"
#include "core/random.h"
#include "recognition/local/internal.h"
#include "recognition/local/match_kernels.h"

namespace {

constexpr int kDim = 352;

// Non-negative rows of unit norm (as SHOT's), around a few cluster centres.
std::vector<float> clustered_rows(int rows, int clusters, double spread, pb::Rng& rng) {
  std::vector<std::vector<double>> centres(clusters, std::vector<double>(kDim));
  for (auto& c : centres)
    for (auto& x : c) x = rng.uniform() < 0.3 ? rng.uniform() : 0.0;
  std::vector<float> out;
  for (int r = 0; r < rows; ++r) {
    const auto& c = centres[rng.uniform_int(0, clusters - 1)];
    std::vector<double> v(kDim);
    double n = 0;
    for (int j = 0; j < kDim; ++j) {
      v[j] = std::max(0.0, c[j] + rng.normal(0, spread));
      n += v[j] * v[j];
    }
    n = std::sqrt(n);
    for (int j = 0; j < kDim; ++j) out.push_back(static_cast<float>(v[j] / n));
  }
  return out;
}

TEST(DescriptorIndex, BlockedSearchEqualsExactScan) {
  pb::Rng rng(7);
  std::vector<float> data = clustered_rows(1500, 40, 0.03, rng);
  // Exact duplicates: equal distances, the lower row must win.
  for (int r = 0; r < 40; ++r) {
    const int src = rng.uniform_int(0, 1499);
    data.insert(data.end(), data.begin() + src * kDim, data.begin() + (src + 1) * kDim);
  }
  const int rows = static_cast<int>(data.size() / kDim);
  pb::local::DescriptorIndex index;
  index.build(data, kDim);
  ASSERT_EQ(index.size(), static_cast<size_t>(rows));

  // Queries: noisy copies of rows (true neighbours close by), exact copies,
  // midpoints of two rows (several neighbours at similar distances) and rows
  // of other clusters (mostly nothing under the threshold).
  std::vector<float> queries;
  for (int q = 0; q < 180; ++q) {
    const int src = rng.uniform_int(0, rows - 1), src2 = rng.uniform_int(0, rows - 1);
    for (int j = 0; j < kDim; ++j) {
      const float x = data[static_cast<size_t>(src) * kDim + j], y = data[static_cast<size_t>(src2) * kDim + j];
      if (q % 3 == 0)
        queries.push_back(x);
      else if (q % 3 == 1)
        queries.push_back(std::max(0.f, x + static_cast<float>(rng.normal(0, 0.02))));
      else
        queries.push_back(0.5f * (x + y));
    }
  }
  const std::vector<float> other = clustered_rows(40, 5, 0.05, rng);
  queries.insert(queries.end(), other.begin(), other.end());
  const int n = static_cast<int>(queries.size() / kDim);

  size_t found = 0;
  for (int k : {1, 3, 10}) {
    for (float thr : {0.05f, 0.25f, 0.6f, 4.f}) {
      std::vector<std::vector<std::pair<int, float>>> blocked(n);
      index.knn_block(queries.data(), n, k, thr, blocked.data());
      for (int i = 0; i < n; ++i) {
        std::vector<std::pair<int, float>> exact;
        index.knn(queries.data() + static_cast<size_t>(i) * kDim, k, thr, exact);
        ASSERT_EQ(blocked[i], exact) << "query " << i << " k " << k << " threshold " << thr;
        found += exact.size();
      }
    }
  }
  EXPECT_GT(found, 400u);  // the comparison is not between empty answers
}

// Capped checks: with a cap at least the row count the answer is the exact
// one bit for bit. With a cap it is exact for at least 95% of the matched
// queries at 64 checks (measured: 300 of 300), while 16 checks miss (210 of
// 300: the cap binds); an approximate answer is never nearer than the exact
// one, stays under the threshold, and does not depend on the blocking.
TEST(DescriptorIndex, CappedChecksAreExactUntilTheCapBindsAndKeepAHighRecall) {
  pb::Rng rng(11);
  const std::vector<float> data = clustered_rows(3000, 60, 0.05, rng);
  const int rows = static_cast<int>(data.size() / kDim);
  pb::local::DescriptorIndex index;
  index.build(data, kDim);
  std::vector<float> queries;
  for (int q = 0; q < 300; ++q) {
    const int src = rng.uniform_int(0, rows - 1);
    for (int j = 0; j < kDim; ++j)
      queries.push_back(std::max(0.f, data[static_cast<size_t>(src) * kDim + j] + static_cast<float>(rng.normal(0, 0.03))));
  }
  const int n = static_cast<int>(queries.size() / kDim);
  const float thr = 0.5f;
  using Result = std::vector<std::vector<std::pair<int, float>>>;
  Result exact(n), capped(n), single(n), all(n);
  index.knn_block(queries.data(), n, 1, thr, exact.data());
  index.knn_block(queries.data(), n, 1, thr, all.data(), rows);
  EXPECT_EQ(all, exact);
  for (int checks : {64, 16}) {
    index.knn_block(queries.data(), n, 1, thr, capped.data(), checks);
    int matched = 0, same = 0;
    for (int i = 0; i < n; ++i) {
      index.knn_block(queries.data() + static_cast<size_t>(i) * kDim, 1, 1, thr, &single[i], checks);
      ASSERT_EQ(single[i], capped[i]) << "query " << i << ": depends on the block";
      if (!capped[i].empty()) {
        ASSERT_FALSE(exact[i].empty());
        EXPECT_GE(capped[i][0].second, exact[i][0].second);
        EXPECT_LT(capped[i][0].second, thr);
      }
      if (exact[i].empty()) continue;
      ++matched;
      same += capped[i] == exact[i];
    }
    ASSERT_GT(matched, 250) << "the queries must mostly have a match";
    if (checks == 64)
      EXPECT_GE(same, matched * 95 / 100) << checks << " checks: " << same << " of " << matched;
    else  // the cap binds: the test compares an approximate search
      EXPECT_LT(same, matched) << checks << " checks found every exact match";
    std::printf("[ recall   ] %d checks: %d of %d matched queries exact\n", checks, same, matched);
  }
}



// The capped search ranks rows by their lower bounds, so every way of
// computing SHOT-sized bounds must give the same bits: the AVX2 kernel and
// the plain loop, for row counts that are not a multiple of its eight lanes
// or of its 256-row tiles and for blocks that are not a multiple of its four
// queries. Each bound is also a lower bound of the exact squared distance,
// up to the search's rounding margin.
TEST(DescriptorIndex, ShotSizedBoundsHaveTheSameBitsOnEveryPath) {
  // Without AVX2 the plain loop is the only path: the bounds are still checked.
  const bool avx2 = pb::cpu_has_avx2();
  if (!avx2) std::printf("no AVX2 on this CPU: the bits comparison is skipped\n");
  pb::Rng rng(23);
  for (const int rows : {1, 7, 300, 2075}) {
    const std::vector<float> data = clustered_rows(rows, 20, 0.05, rng);
    pb::local::DescriptorIndex index;
    index.build(data, kDim);
    for (const int n : {1, 3, 4, 37}) {
      std::vector<float> queries;
      for (int q = 0; q < n; ++q) {
        const int src = rng.uniform_int(0, rows - 1);
        for (int j = 0; j < kDim; ++j)
          queries.push_back(
              std::max(0.f, data[static_cast<size_t>(src) * kDim + j] + static_cast<float>(rng.normal(0, 0.03))));
      }
      index.set_avx2_bounds(false);
      const std::vector<float> plain = index.lower_bounds(queries.data(), n);
      index.set_avx2_bounds(true);
      const std::vector<float> fast = index.lower_bounds(queries.data(), n);
      ASSERT_EQ(plain.size(), static_cast<size_t>(rows) * static_cast<size_t>(n));
      ASSERT_EQ(fast.size(), plain.size());
      for (size_t e = 0; avx2 && e < plain.size(); ++e)
        ASSERT_EQ(std::memcmp(&plain[e], &fast[e], sizeof(float)), 0)
            << "rows " << rows << " queries " << n << ": query " << e / static_cast<size_t>(rows) << ", row "
            << e % static_cast<size_t>(rows) << ": " << plain[e] << " vs " << fast[e];
      for (int i = 0; i < n; ++i) {
        float qn = 0;  // the query's squared norm, in the search's margin (rows: unit norm)
        for (int j = 0; j < kDim; ++j) {
          const float x = queries[static_cast<size_t>(i) * kDim + j];
          qn += x * x;
        }
        for (int r = 0; r < rows; ++r) {
          float exact = 0;
          for (int j = 0; j < kDim; ++j) {
            const float t = queries[static_cast<size_t>(i) * kDim + j] - data[static_cast<size_t>(r) * kDim + j];
            exact += t * t;
          }
          ASSERT_LE(plain[static_cast<size_t>(i) * static_cast<size_t>(rows) + static_cast<size_t>(r)],
                    exact + 1e-4f * (qn + 1.f))
              << "rows " << rows << " query " << i << " row " << r;
        }
      }
    }
  }
}

// The AVX2 bounds kernel's smallest bound per query (what knn_block's first
// pass looks for, found as the bounds are written) is the smallest of the
// bounds it writes, for row counts off its eight lanes and 256-row tiles
// and blocks off its four queries.
TEST(DescriptorIndex, LongBoundsKernelGivesEachQuerysSmallestBound) {
  if (!pb::cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU";
  pb::Rng rng(41);
  constexpr int kAxes = pb::local::kProjDim;
  for (const size_t rows : {size_t{1}, size_t{13}, size_t{256}, size_t{2075}}) {
    std::vector<float> zt(rows * kAxes), psq(rows);
    for (size_t r = 0; r < rows; ++r)
      for (int a = 0; a < kAxes; ++a) {
        const float v = static_cast<float>(rng.normal(0, 0.3));
        zt[static_cast<size_t>(a) * rows + r] = v;
        psq[r] += v * v;
      }
    for (const int nq : {1, 4, 7, 37}) {
      std::vector<float> zq(static_cast<size_t>(nq) * kAxes), zn(static_cast<size_t>(nq));
      for (int i = 0; i < nq; ++i)
        for (int a = 0; a < kAxes; ++a) {
          const float v = static_cast<float>(rng.normal(0, 0.3));
          zq[static_cast<size_t>(i) * kAxes + static_cast<size_t>(a)] = v;
          zn[static_cast<size_t>(i)] += v * v;
        }
      std::vector<float> lbs(static_cast<size_t>(nq) * rows), mins(static_cast<size_t>(nq));
      pb::local::long_bounds_avx2(zq.data(), zn.data(), nq, kAxes, zt.data(), psq.data(), rows, lbs.data(),
                                  mins.data());
      for (int i = 0; i < nq; ++i) {
        const auto first = lbs.begin() + static_cast<long>(static_cast<size_t>(i) * rows);
        const float want = *std::min_element(first, first + static_cast<long>(rows));
        ASSERT_EQ(std::memcmp(&mins[static_cast<size_t>(i)], &want, sizeof want), 0)
            << "rows " << rows << " queries " << nq << ": query " << i;
      }
    }
  }
}

// The capped search's candidates: the cap smallest (value, index) pairs
// under the limit, the same set as listing every pair under it and keeping
// the cap smallest with nth_element (the plain way), with ties, NaN and
// lengths that are not a multiple of four or eight, on both paths (SSE, and
// AVX2 where the CPU has it).
TEST(DescriptorIndex, SmallestAtMostEqualsListingThenNthElement) {
  pb::Rng rng(5);
  for (int trial = 0; trial < 200; ++trial) {
    const size_t n = static_cast<size_t>(rng.uniform_int(0, 3001));
    std::vector<float> v(n);
    for (float& x : v) {
      const double u = rng.uniform();
      x = u < 0.02 ? std::numeric_limits<float>::quiet_NaN()
                   : static_cast<float>(u < 0.3 ? rng.uniform_int(0, 20) : rng.uniform(0, 20));  // many ties
    }
    const float limit = static_cast<float>(rng.uniform(0, 25));
    const size_t cap = static_cast<size_t>(rng.uniform_int(0, 100));
    std::vector<std::pair<float, int>> want;
    for (size_t r = 0; r < n; ++r)
      if (v[r] <= limit) want.emplace_back(v[r], static_cast<int>(r));
    if (want.size() > cap) {
      std::nth_element(want.begin(), want.begin() + static_cast<long>(cap), want.end());
      want.resize(cap);
    }
    std::sort(want.begin(), want.end());
    for (const bool avx2 : {false, true}) {
      if (avx2 && !pb::cpu_has_avx2()) continue;
      std::vector<std::pair<float, int>> got;
      pb::local::smallest_at_most(v.data(), n, limit, cap, got, avx2);
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, want) << "trial " << trial << ": n " << n << " cap " << cap << " limit " << limit << " avx2 "
                           << avx2;
    }
  }
}

// FPFH-sized rows (33: the lower bound from 12 principal axes), with the
// bounds from Eigen's product and, where the CPU has AVX2 and FMA, from the
// fused kernel (3030 rows: the kernel's tail too; blocks of any size): the
// blocked search equals the exact scan bit for bit, duplicate rows (ties:
// the lower row) included, and the search bounded by the threshold gives
// what an unbounded k-nearest search gives once the rows at or above the
// threshold are dropped, for several k and thresholds.
TEST(DescriptorIndex, FpfhSizedBlockedSearchEqualsExactScanUnderEveryThreshold) {
  constexpr int kFpfh = 33;
  pb::Rng rng(11);
  std::vector<float> data;
  for (int r = 0; r < 3000; ++r)
    for (int j = 0; j < kFpfh; ++j) data.push_back(static_cast<float>(rng.uniform(0, 30)));
  for (int r = 0; r < 30; ++r) {  // exact duplicates
    const int src = rng.uniform_int(0, 2999);
    data.insert(data.end(), data.begin() + src * kFpfh, data.begin() + (src + 1) * kFpfh);
  }
  pb::local::DescriptorIndex index;
  index.build(data, kFpfh);
  std::vector<float> queries;
  for (int q = 0; q < 300; ++q) {
    const int src = rng.uniform_int(0, 3029);
    const double sigma = q % 3 == 0 ? 0.0 : q % 3 == 1 ? 2.0 : 6.0;  // exact copies hit the duplicates' ties
    for (int j = 0; j < kFpfh; ++j)
      queries.push_back(data[static_cast<size_t>(src) * kFpfh + j] + static_cast<float>(rng.normal(0, sigma)));
  }
  const int n = static_cast<int>(queries.size() / kFpfh);
  const float inf = std::numeric_limits<float>::infinity();
  for (const bool avx2 : {false, true}) {
    SCOPED_TRACE(avx2 ? "AVX2 bounds" : "Eigen's bounds");
    index.set_avx2_bounds(avx2);
    size_t found = 0, dropped = 0;
    for (int k : {1, 3, 10}) {
      std::vector<std::vector<std::pair<int, float>>> unbounded(n);
      index.knn_block(queries.data(), n, k, inf, unbounded.data());
      for (float thr : {300.f, 1500.f, 4000.f}) {
        std::vector<std::vector<std::pair<int, float>>> bounded(n);
        index.knn_block(queries.data(), n, k, thr, bounded.data());
        for (int i = 0; i < n; ++i) {
          std::vector<std::pair<int, float>> exact, exact_all;
          index.knn(queries.data() + static_cast<size_t>(i) * kFpfh, k, thr, exact);
          index.knn(queries.data() + static_cast<size_t>(i) * kFpfh, k, inf, exact_all);
          ASSERT_EQ(bounded[i], exact) << "query " << i << " k " << k << " threshold " << thr;
          ASSERT_EQ(unbounded[i], exact_all) << "query " << i << " k " << k;
          ASSERT_EQ(exact_all.size(), static_cast<size_t>(k));
          std::vector<std::pair<int, float>> under;
          for (const auto& e : exact_all)
            if (e.second < thr) under.push_back(e);
          ASSERT_EQ(bounded[i], under) << "query " << i << " k " << k << " threshold " << thr;
          found += under.size();
          dropped += exact_all.size() - under.size();
        }
      }
    }
    EXPECT_GT(found, 500u);    // not all empty
    EXPECT_GT(dropped, 500u);  // and the threshold binds
    // Blocks that are not a multiple of the kernel's four queries (its
    // one-query tail), at any offset: each query still gets the exact scan's
    // answer.
    for (const int block : {1, 3, 5, 7}) {
      for (int first = 0; first + block <= 40; first += block) {
        std::vector<std::vector<std::pair<int, float>>> got(static_cast<size_t>(block));
        index.knn_block(queries.data() + static_cast<size_t>(first) * kFpfh, block, 3, 1500.f, got.data());
        for (int i = 0; i < block; ++i) {
          std::vector<std::pair<int, float>> exact;
          index.knn(queries.data() + static_cast<size_t>(first + i) * kFpfh, 3, 1500.f, exact);
          ASSERT_EQ(got[static_cast<size_t>(i)], exact) << "block " << block << ", query " << first + i;
        }
      }
    }
  }
}

}  // namespace
