// Seeded random streams. Every random choice in posebench draws from an Rng
// derived from the config's seed and the identity of the work item (scene,
// image, trial...), never from global state or the clock, so results are the
// same for any thread count. The distributions are implemented here (not
// std::normal_distribution) so the numbers are identical across standard
// libraries.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <vector>

namespace pb {

// SplitMix64 mixing of a base seed with stream identifiers.
uint64_t derive_seed(uint64_t base, std::initializer_list<uint64_t> ids);

class Rng {
 public:
  explicit Rng(uint64_t seed);
  uint64_t next_u64();                       // xoshiro256**
  double uniform();                          // [0, 1)
  double uniform(double lo, double hi);      // [lo, hi)
  int uniform_int(int lo, int hi);           // inclusive range [lo, hi]
  double normal(double mean = 0.0, double sigma = 1.0);  // Box-Muller
  bool bernoulli(double p) { return uniform() < p; }
  // UniformRandomBitGenerator interface for std::shuffle and friends.
  using result_type = uint64_t;
  static constexpr uint64_t min() { return 0; }
  static constexpr uint64_t max() { return ~uint64_t(0); }
  uint64_t operator()() { return next_u64(); }

 private:
  uint64_t s_[4];
  bool has_spare_ = false;
  double spare_ = 0.0;
};

// The first k of a seeded Fisher-Yates shuffle of 0..n-1, in index order (all
// of them when k is 0 or not below n): a random subset of points (ICP's
// source points, the pipeline's screening subset).
std::vector<std::size_t> sample_indices(std::size_t n, int k, uint64_t seed);

}  // namespace pb
