// Scatter3 against the Eigen expressions of the same sums: the lower triangle of
// the sum of d d^T (normals, BOARD) and of w d d^T (the SHOT frame), bit for
// bit, over random neighbourhoods; the eigensolvers read only that triangle,
// so the normals and frames stay the same.
#include <gtest/gtest.h>

#include "core/random.h"
#include "recognition/scatter.h"

namespace {

using pb::Mat3;
using pb::Vec3;

TEST(Scatter3, EqualsEigensOuterProductSumsInTheLowerTriangleBitForBit) {
  pb::Rng rng(7);
  int compared = 0;
  for (int t = 0; t < 20000; ++t) {
    const int n = 1 + static_cast<int>(rng.uniform(0, 40));
    Mat3 plain = Mat3::Zero(), weighted = Mat3::Zero();
    pb::Scatter3 s, sw;
    for (int k = 0; k < n; ++k) {
      const Vec3 d(rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(-300, 300));
      const double w = rng.uniform(0, 60);
      plain.noalias() += d * d.transpose();
      weighted.noalias() += w * (d * d.transpose());
      s.add(d);
      sw.add_weighted(w, d);
    }
    const Mat3 a = s.matrix(), b = sw.matrix();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) {
        ASSERT_EQ(a(i, j), plain(i, j)) << "trial " << t << " entry " << i << j;
        ASSERT_EQ(b(i, j), weighted(i, j)) << "trial " << t << " entry " << i << j;
        ++compared;
      }
    ASSERT_EQ(a, a.transpose());
    ASSERT_EQ(b, b.transpose());
  }
  EXPECT_EQ(compared, 20000 * 6);
}

}  // namespace
