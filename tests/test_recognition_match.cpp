// The descriptor index's blocked search (a projected lower bound, then exact
// distances) against its exact linear scan (knn, one query at a time), on
// SHOT-sized descriptors: clustered rows, exact duplicate rows (ties), noisy
// copies of rows and unrelated queries, for several k and thresholds. The
// results must be equal bit for bit: rows, order and distances.
#include <gtest/gtest.h>

#include "core/random.h"
#include "recognition/local/internal.h"

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

}  // namespace
