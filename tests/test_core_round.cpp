// core/round.h: round_half_away is std::round bit for bit (a zero result
// aside, always +0.0), on exact halves of both signs, the values either side
// of them, signed zeros, the 2^52 limit, infinities, NaN and random values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/random.h"
#include "core/round.h"

using namespace pb;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

}  // namespace

TEST(RoundHalfAway, IsStdRoundBitForBit) {
  std::vector<double> xs = {0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994,
                            4503599627370495.5, -4503599627370495.5, 4503599627370496.0, 9007199254740993.0,
                            std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::denorm_min(), -0.3, 0.3};
  for (double h = 0.5; h < 70000; h = h * 1.7 + 1) {  // halves and their neighbours, both signs
    const double half = std::floor(h) + 0.5;
    for (double x : {half, std::nextafter(half, 0.0), std::nextafter(half, 1e300)}) {
      xs.push_back(x);
      xs.push_back(-x);
    }
  }
  Rng rng(1);
  for (int i = 0; i < 100000; ++i) xs.push_back(rng.uniform(-70000.0, 70000.0));
  size_t differ = 0;
  for (double x : xs) {
    const double got = round_half_away(x), want = std::round(x);
    differ += !(same_bits(got, want) || (want == 0.0 && same_bits(got, 0.0)));
  }
  EXPECT_EQ(differ, 0u) << "of " << xs.size();
  EXPECT_TRUE(same_bits(round_half_away(-0.3), 0.0));  // std::round gives -0.0 here
  EXPECT_TRUE(std::isnan(round_half_away(std::nan(""))));
}
