// McNemar's exact test (eval/stats.h) against values computed by hand.
#include <gtest/gtest.h>

#include "eval/stats.h"

using namespace pb;

TEST(EvalStats, McNemarExact) {
  EXPECT_DOUBLE_EQ(mcnemar_exact_p(0, 0), 1.0);
  EXPECT_NEAR(mcnemar_exact_p(0, 5), 2.0 / 32.0, 1e-12);
  EXPECT_NEAR(mcnemar_exact_p(5, 0), 2.0 / 32.0, 1e-12);
  EXPECT_NEAR(mcnemar_exact_p(2, 1), 1.0, 1e-12);
  // b = 1, c = 9: 2 (1 + 10) / 1024
  EXPECT_NEAR(mcnemar_exact_p(1, 9), 22.0 / 1024.0, 1e-12);
}
