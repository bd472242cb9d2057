// Rounding to the nearest integer, halves away from zero: std::round's
// value without its library call.
#pragma once

#include <cmath>
#include <cstdint>

namespace pb {

// std::round(x), bit for bit, except that a zero result is always +0.0
// (std::round(-0.3) is -0.0). For |x| < 2^52, x minus its truncation is
// exact, so comparing it with 0.5 decides; larger values, infinities and NaN
// go to std::round. The step is added without a branch (the fraction's side
// of 0.5 is a coin toss on noisy data): t comes from an integer, so it is
// never -0.0 and t + 0.0 is t.
inline double round_half_away(double x) {
  if (!(std::abs(x) < 4503599627370496.0)) return std::round(x);
  const double t = static_cast<double>(static_cast<int64_t>(x));
  const double f = x - t;
  const double up = f >= 0.5 ? 1.0 : 0.0, down = f <= -0.5 ? 1.0 : 0.0;
  return t + up - down;
}

}  // namespace pb
