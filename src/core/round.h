// Rounding to the nearest integer, halves away from zero: std::round's
// value without its library call.
#pragma once

#include <cmath>
#include <cstdint>

namespace pb {

// std::round(x), bit for bit. For |x| < 2^52, x minus its truncation is
// exact, so comparing it with 0.5 decides; larger values, infinities and NaN
// go to std::round.
inline double round_half_away(double x) {
  if (!(std::abs(x) < 4503599627370496.0)) return std::round(x);
  const double t = static_cast<double>(static_cast<int64_t>(x));
  const double f = x - t;
  return f >= 0.5 ? t + 1.0 : f <= -0.5 ? t - 1.0 : t;
}

}  // namespace pb
