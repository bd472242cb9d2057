#include "eval/stats.h"

#include <algorithm>
#include <cmath>

namespace pb {

Proportion wilson(int k, int n, double z) {
  Proportion p;
  p.k = k;
  p.n = n;
  if (n <= 0) return p;
  const double nn = n, ph = k / nn, z2 = z * z;
  const double centre = (ph + z2 / (2 * nn)) / (1 + z2 / nn);
  const double half = z / (1 + z2 / nn) * std::sqrt(ph * (1 - ph) / nn + z2 / (4 * nn * nn));
  p.lo = std::max(0.0, centre - half);
  p.hi = std::min(1.0, centre + half);
  return p;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t i = static_cast<size_t>(std::floor(pos));
  const size_t j = std::min(i + 1, v.size() - 1);
  return v[i] + (pos - static_cast<double>(i)) * (v[j] - v[i]);
}

double mcnemar_exact_p(int b, int c) {
  const int n = b + c, k = std::min(b, c);
  if (n <= 0) return 1.0;
  // P(X <= k) by summing the pmf in logs (n may be in the thousands).
  double tail = 0;
  for (int i = 0; i <= k; ++i)
    tail += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) - n * std::log(2.0));
  return std::min(1.0, 2.0 * tail);
}

}  // namespace pb
