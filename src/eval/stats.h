// Small statistics of a sweep's outcomes. PCL-free.
#pragma once

#include <vector>

namespace pb {

// A binomial proportion k of n with its Wilson score interval (z = 1.96:
// 95%). n = 0 gives the whole [0, 1].
struct Proportion {
  int k = 0, n = 0;
  double lo = 0, hi = 1;
  double value() const { return n > 0 ? static_cast<double>(k) / n : 0.0; }
};
Proportion wilson(int k, int n, double z = 1.959963984540054);

// The q-quantile (0..1) by linear interpolation between order statistics
// (numpy's default); NaN for an empty sample.
double quantile(std::vector<double> v, double q);

// McNemar's exact two-sided p for paired binary outcomes: b pairs with only
// the first outcome, c with only the second; min(1, 2 P(X <= min(b, c)))
// for X ~ Binomial(b + c, 1/2). 1 when b + c = 0.
double mcnemar_exact_p(int b, int c);
inline double median(std::vector<double> v) { return quantile(std::move(v), 0.5); }

}  // namespace pb
