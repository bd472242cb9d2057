#include "core/random.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace pb {

static uint64_t splitmix64(uint64_t& x) {
  uint64_t z = (x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

uint64_t derive_seed(uint64_t base, std::initializer_list<uint64_t> ids) {
  uint64_t x = base;
  uint64_t h = splitmix64(x);
  for (uint64_t id : ids) {
    x = h ^ (id + 0x632BE59BD9B4E019ull);
    h = splitmix64(x);
  }
  return h;
}

Rng::Rng(uint64_t seed) {
  uint64_t x = seed;
  for (auto& s : s_) s = splitmix64(x);
}

static inline uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

uint64_t Rng::next_u64() {
  const uint64_t result = rotl(s_[1] * 5, 7) * 9;
  const uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

double Rng::uniform() { return (next_u64() >> 11) * 0x1.0p-53; }

double Rng::uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

int Rng::uniform_int(int lo, int hi) {
  const uint64_t span = static_cast<uint64_t>(static_cast<int64_t>(hi) - lo) + 1;
  return lo + static_cast<int>(next_u64() % span);
}

double Rng::normal(double mean, double sigma) {
  if (has_spare_) {
    has_spare_ = false;
    return mean + sigma * spare_;
  }
  double u1;
  do u1 = uniform(); while (u1 <= 1e-300);
  const double u2 = uniform();
  const double r = std::sqrt(-2.0 * std::log(u1));
  spare_ = r * std::sin(2.0 * M_PI * u2);
  has_spare_ = true;
  return mean + sigma * r * std::cos(2.0 * M_PI * u2);
}

std::vector<size_t> sample_indices(size_t n, int k, uint64_t seed) {
  std::vector<size_t> idx(n);
  std::iota(idx.begin(), idx.end(), size_t(0));
  if (k <= 0 || static_cast<size_t>(k) >= n) return idx;
  Rng rng(seed);
  const size_t kk = static_cast<size_t>(k);
  for (size_t i = 0; i < kk; ++i) {
    const size_t j = i + static_cast<size_t>(rng.uniform_int(0, static_cast<int>(n - i - 1)));
    std::swap(idx[i], idx[j]);
  }
  idx.resize(kk);
  std::sort(idx.begin(), idx.end());
  return idx;
}

}  // namespace pb
