// core/trig.h: series_acos and series_atan2_double lie within 4 ulp of the
// true angle (long double libm as the reference) on random arguments at
// every scale, give the exact angles at the axes and the ends, and
// core/trig_avx2.h's four lanes give the scalar functions' bits.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "core/cpu.h"
#include "core/random.h"
#include "core/trig.h"
#if defined(__x86_64__) || defined(__i386__)
#include "core/trig_avx2.h"
#endif

using namespace pb;

namespace {

// |v - ref| in units of the ulp of the double nearest ref.
double ulps(double v, long double ref) {
  const double r = static_cast<double>(ref);
  const double ulp = std::nextafter(std::fabs(r), INFINITY) - std::fabs(r);
  return static_cast<double>(std::fabs(static_cast<long double>(v) - ref) / ulp);
}

struct Args {
  std::vector<double> c, y, x;  // cosines in [-1, 1]; coordinates at every scale
};

Args random_args(size_t n) {
  Rng rng(43);
  Args a;
  for (size_t i = 0; i < n; ++i) {
    const double scale = std::ldexp(1.0, rng.uniform_int(-40, 40));
    a.c.push_back(i % 3 == 0 ? std::ldexp(rng.uniform(-1, 1), -rng.uniform_int(0, 60)) : rng.uniform(-1, 1));
    a.y.push_back(rng.uniform(-1, 1) * scale);
    a.x.push_back(rng.uniform(-1, 1) * scale);
  }
  return a;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2"))) void lanes(const Args& a, std::vector<double>* acos_out,
                                           std::vector<double>* atan2_out) {
  for (size_t i = 0; i + 4 <= a.c.size(); i += 4) {
    _mm256_storeu_pd(acos_out->data() + i, series_acos4(_mm256_loadu_pd(a.c.data() + i)));
    _mm256_storeu_pd(atan2_out->data() + i,
                     series_atan2_double4(_mm256_loadu_pd(a.y.data() + i), _mm256_loadu_pd(a.x.data() + i)));
  }
}
#endif

}  // namespace

TEST(Trig, WithinFourUlpOfTheTrueAngle) {
  const Args a = random_args(2000000);
  double worst_acos = 0, worst_atan2 = 0;
  for (size_t i = 0; i < a.c.size(); ++i) {
    worst_acos = std::max(worst_acos, ulps(series_acos(a.c[i]), acosl(static_cast<long double>(a.c[i]))));
    worst_atan2 = std::max(worst_atan2, ulps(series_atan2_double(a.y[i], a.x[i]),
                                             atan2l(static_cast<long double>(a.y[i]), a.x[i])));
  }
  // Measured on these 2e6 arguments: 3.4 and 3.0 ulp.
  EXPECT_LT(worst_acos, 4.0);
  EXPECT_LT(worst_atan2, 4.0);
  // The quarters' constants are the doubles nearest atan(k / 4).
  for (int k = 0; k <= 4; ++k)
    EXPECT_TRUE(same_bits(kAtanQuarters[k], static_cast<double>(atanl(k / 4.0L)))) << k;
}

TEST(Trig, ExactAtTheAxesAndTheEnds) {
  EXPECT_TRUE(same_bits(series_acos(0.0), M_PI / 2));
  EXPECT_TRUE(same_bits(series_acos(-0.0), M_PI / 2));
  EXPECT_TRUE(same_bits(series_acos(1.0), 0.0));
  EXPECT_TRUE(same_bits(series_acos(-1.0), M_PI));
  EXPECT_TRUE(std::isnan(series_acos(NAN)));
  EXPECT_TRUE(same_bits(series_atan2_double(0.0, 2.0), 0.0));
  EXPECT_TRUE(same_bits(series_atan2_double(0.0, -2.0), M_PI));
  EXPECT_TRUE(same_bits(series_atan2_double(3.0, 0.0), M_PI / 2));
  EXPECT_TRUE(same_bits(series_atan2_double(-3.0, 0.0), -M_PI / 2));
  EXPECT_TRUE(same_bits(series_atan2_double(5.0, 5.0), M_PI / 4));
  EXPECT_TRUE(same_bits(series_atan2_double(-5.0, -5.0), -(M_PI - M_PI / 4)));
  // A tiny angle is its tangent (no underflow to 0).
  EXPECT_TRUE(same_bits(series_atan2_double(1e-300, 1.0), 1e-300));
}

TEST(Trig, FourLanesGiveTheScalarBits) {
#if defined(__x86_64__) || defined(__i386__)
  if (!cpu_has_avx2()) GTEST_SKIP() << "the CPU has no AVX2";
  Args a = random_args(400000);
  // The ends, the axes and a NaN among the random lanes.
  const double special[] = {0.0, -0.0, 1.0, -1.0, 0.5, -0.5, NAN, 0.125};
  for (size_t k = 0; k < 8; ++k) a.c[k] = special[k], a.y[k] = special[7 - k], a.x[k] = special[k];
  a.y[6] = 0, a.x[6] = -1;  // the NaN lane: acos only
  std::vector<double> acos4(a.c.size()), atan24(a.c.size());
  lanes(a, &acos4, &atan24);
  size_t wrong = 0;
  for (size_t i = 0; i < a.c.size(); ++i) {
    const bool acos_ok = same_bits(acos4[i], series_acos(a.c[i])) || (std::isnan(acos4[i]) && std::isnan(a.c[i]));
    const bool both_zero = a.y[i] == 0 && a.x[i] == 0;
    const double ref = series_atan2_double(a.y[i], a.x[i]);
    const bool atan2_ok = both_zero || same_bits(atan24[i], ref) || (std::isnan(atan24[i]) && std::isnan(ref));
    if ((!acos_ok || !atan2_ok) && ++wrong <= 3)
      ADD_FAILURE() << "argument " << i << ": acos(" << a.c[i] << ") atan2(" << a.y[i] << ", " << a.x[i] << ")";
  }
  EXPECT_EQ(wrong, 0u);
#else
  GTEST_SKIP() << "not an x86 build";
#endif
}
