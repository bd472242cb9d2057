// acos and atan2 in double from a short series, each within a few ulp of the
// true angle, for code that needs the angle's value to double precision
// (SHOT's votes interpolate with it) many times per frame. libm's acos and
// atan2 are correctly rounded or close to it but took about a tenth of the
// warehouse SHOT frame (perf record samples; results/bench/README.md).
// These give the same bits on every machine (no fused multiply-add: build
// callers with -ffp-contract=off), and core/trig_avx2.h gives them for four
// lanes.
// (core/atan2_bin.h's series_atan2 is the coarser sibling, within 2e-8,
// for code that only bins the angle and lets atan2f decide near an edge.)
//
// atan t for t in [0, 1]: with c the nearest quarter, atan t = atan c +
// atan u, u = (t - c) / (1 + t c), |u| <= 1/8 (t - c is exact: c / 2 <= t
// <= 2 c). The series of atan u to u^19 leaves less than |u|^21 / 21, under
// 1e-19 |u|. atan c is a constant (its double, from mpmath at 40 digits).
#pragma once

#include <cmath>

namespace pb {

// atan(k / 4), k = 0 .. 4, each the double nearest the true value.
inline constexpr double kAtanQuarters[5] = {0.0, 0.24497866312686414, 0.4636476090008061, 0.6435011087932844,
                                            0.7853981633974483};

// The series' coefficients (-1)^k / (2k + 1), k = 9 down to 1, for Horner's
// rule in u^2.
inline constexpr double kAtanSeries[9] = {-1.0 / 19, 1.0 / 17, -1.0 / 15, 1.0 / 13, -1.0 / 11,
                                          1.0 / 9,   -1.0 / 7, 1.0 / 5,   -1.0 / 3};

// atan t for t in [0, 1] (NaN for NaN).
inline double atan_unit(double t) {
  if (std::isnan(t)) return t;
  const double q = std::floor(t * 4 + 0.5);
  const double c = q * 0.25;
  const double u = (t - c) / (1 + t * c);
  const double w = u * u;
  double s = kAtanSeries[0];
  for (int k = 1; k < 9; ++k) s = s * w + kAtanSeries[k];
  return kAtanQuarters[static_cast<int>(q)] + (u + u * w * s);
}

// acos x for x in [-1, 1]: 2 atan sqrt((1 - |x|) / (1 + |x|)), taken from pi
// for negative x (NaN for NaN).
inline double series_acos(double x) {
  const double a = std::fabs(x);
  const double half = atan_unit(std::sqrt((1 - a) / (1 + a)));
  return x < 0 ? M_PI - 2 * half : 2 * half;
}

// atan2(y, x) for finite x and y, not both zero (y = -0 counts as +0): the
// octant's angle atan_unit of min / max, then reflected as the signs and the
// larger coordinate say.
inline double series_atan2_double(double y, double x) {
  const double ay = std::fabs(y), ax = std::fabs(x);
  const bool steep = ay > ax;
  double r = atan_unit(steep ? ax / ay : ay / ax);
  if (steep) r = M_PI / 2 - r;
  if (x < 0) r = M_PI - r;
  return y < 0 ? -r : r;
}

}  // namespace pb
