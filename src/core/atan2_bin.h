// The bin of an angle atan2(y, x) without atan2f where the bin is in no
// doubt. PPF's and FPFH's pair features bin an atan2f angle and use nothing
// else of it; this gives the same bin, with atan2f's value deciding only
// near a bin edge.
#pragma once

#include <cmath>

namespace pb {

// atan2(y, x) in double from its series, within 2e-8 of the true angle (not
// libm's value): the octant's ratio t in [0, 1], brought to |t| <= tan(pi /
// 8) by atan t = pi / 4 + atan((t - 1) / (t + 1)), where the alternating
// series to t^15 leaves less than |t|^17 / 17.
inline double series_atan2(float yf, float xf) {
  const double y = yf, x = xf, ay = std::fabs(y), ax = std::fabs(x);
  const bool steep = ay > ax;
  double t = steep ? ax / ay : ay / ax;
  double base = 0;
  if (t > 0.41421356237309503) {
    t = (t - 1) / (t + 1);
    base = M_PI / 4;
  }
  const double t2 = t * t;
  double s = -1.0 / 15;
  for (const double c : {1.0 / 13, -1.0 / 11, 1.0 / 9, -1.0 / 7, 1.0 / 5, -1.0 / 3, 1.0}) s = s * t2 + c;
  double r = base + t * s;
  if (steep) r = M_PI / 2 - r;
  if (x < 0) r = M_PI - r;
  return y < 0 ? -r : r;
}

// bin(std::atan2(y, x)) for a `bin` non-decreasing in the (float) angle.
// The series' angle is within 2e-8 of the true one and atan2f's within 1
// ulp (under 4e-7 on [-pi, pi]), so atan2f's value lies within 1e-5 of the
// series' both ways; where `bin` is the same at both ends of that window it
// is atan2f's bin. Otherwise (an edge within the window, a zero argument
// with its sign, a non-finite one) atan2f decides.
inline constexpr double kAtan2BinWindow = 1e-5;
template <class Bin>
inline auto binned_atan2(float y, float x, const Bin& bin) -> decltype(bin(0.0f)) {
  if (y != 0.0f && x != 0.0f && std::isfinite(y) && std::isfinite(x)) {
    const double a = series_atan2(y, x);
    const auto lo = bin(static_cast<float>(a - kAtan2BinWindow));
    if (lo == bin(static_cast<float>(a + kAtan2BinWindow))) return lo;
  }
  return bin(std::atan2(y, x));
}

}  // namespace pb
