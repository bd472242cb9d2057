// core/atan2_bin.h: binned_atan2 gives bin(std::atan2(y, x)) for bin
// functions non-decreasing in the angle: FPFH's 11 bins (floor in double of
// (f1 + pi) / 2 pi), a fine one of 3600 bins, a coarse one whose edges lie
// off every multiple of pi, and PPF's (floor(f1 / step) in float, four
// steps); on random directions at every scale, directions within a few ulps
// of each edge, and signed zeros, infinities and NaN.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "core/atan2_bin.h"
#include "core/random.h"

using namespace pb;

namespace {

void check_bins(const char* name, const std::function<int(float)>& bin, const std::vector<double>& edges) {
  size_t wrong = 0, checked = 0;
  auto check = [&](float y, float x) {
    ++checked;
    const int ours = binned_atan2(y, x, bin), ref = bin(std::atan2(y, x));
    if (ours != ref && ++wrong <= 3) ADD_FAILURE() << name << ": y " << y << " x " << x << ": " << ours << " vs " << ref;
  };
  Rng rng(3);
  for (int i = 0; i < 1000000; ++i) {
    const float scale = std::ldexp(1.f, rng.uniform_int(-60, 60));
    check(static_cast<float>(rng.uniform(-1, 1)) * scale, static_cast<float>(rng.uniform(-1, 1)) * scale);
  }
  for (const double edge : edges)
    for (const double off : {0.0, 1e-7, -1e-7, 3e-6, -3e-6, 2e-5, -2e-5}) {
      float y = static_cast<float>(std::sin(edge + off)), x = static_cast<float>(std::cos(edge + off));
      for (int u = 0; u < 6; ++u) {
        check(y, x);
        check(y * 250.f, x * 250.f);
        y = std::nextafter(y, u % 2 ? 2.f : -2.f);
        x = std::nextafter(x, u % 3 ? -2.f : 2.f);
      }
    }
  const float inf = std::numeric_limits<float>::infinity();
  const float special[] = {0.f, -0.f, 1.f, -1.f, 1e-30f, -1e-45f, 3e38f, inf, -inf,
                           std::numeric_limits<float>::quiet_NaN()};
  for (float y : special)
    for (float x : special) check(y, x);
  EXPECT_EQ(wrong, 0u) << name << ", of " << checked;
}

std::vector<double> edges_every(double first, double step, double last) {
  std::vector<double> e;
  for (double a = first; a <= last + 1e-12; a += step) e.push_back(a);
  return e;
}

}  // namespace

TEST(BinnedAtan2, EqualsTheBinOfAtan2f) {
  const double inv_2pi = static_cast<double>(1.0f / (2.0f * static_cast<float>(M_PI)));
  check_bins("fpfh", [inv_2pi](float f1) {
    const double x = 11 * ((f1 + M_PI) * inv_2pi);
    return !(x >= 0) ? 0 : std::min(static_cast<int>(std::floor(x)), 10);
  }, edges_every(-M_PI, 2 * M_PI / 11, M_PI));
  check_bins("fine", [](float a) { return static_cast<int>(std::floor(a / 0.00174532925f)); },
             edges_every(-M_PI, 0.00174532925 * 97, M_PI));
  check_bins("off pi", [](float a) { return static_cast<int>(std::floor((a + 0.3f) / 0.7f)); },
             edges_every(-0.3 - 4 * 0.7, 0.7, M_PI));
  for (const double deg : {12.0, 7.0, 25.3, 1.0}) {  // PPF's feature bins: floor(f1 / step) in float
    const float step = static_cast<float>(deg * M_PI / 180.0);
    check_bins("ppf", [step](float a) { return static_cast<int>(std::floor(a / step)); },
               edges_every(-std::ceil(M_PI / step) * step, step, M_PI));
  }
}

// The series alone: within 2e-8 of the double atan2 everywhere.
TEST(BinnedAtan2, SeriesIsWithinItsBound) {
  Rng rng(4);
  double worst = 0;
  for (int i = 0; i < 1000000; ++i) {
    const float y = static_cast<float>(rng.uniform(-1, 1)), x = static_cast<float>(rng.uniform(-1, 1));
    if (y == 0 && x == 0) continue;
    worst = std::max(worst, std::abs(series_atan2(y, x) - std::atan2(static_cast<double>(y), static_cast<double>(x))));
  }
  EXPECT_LT(worst, 2e-8);
}
