#include "runner/shard.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <numeric>

#include "core/error.h"
#include "core/hash.h"

namespace pb {

std::string Shard::name() const { return std::to_string(index) + "-of-" + std::to_string(count); }
std::string Shard::label() const { return std::to_string(index) + "/" + std::to_string(count); }

namespace {

bool parse_int(const std::string& text, long* out) {
  if (text.empty() || text.size() > 9) return false;
  for (const char c : text)
    if (c < '0' || c > '9') return false;
  *out = std::strtol(text.c_str(), nullptr, 10);
  return true;
}

}  // namespace

Shard parse_shard(const std::string& text) {
  const size_t slash = text.find('/');
  long i = -1, n = -1;
  if (slash == std::string::npos || !parse_int(text.substr(0, slash), &i) || !parse_int(text.substr(slash + 1), &n))
    throw InputError("", "--shard", "'" + text + "' is not I/N (two non-negative integers, e.g. 0/4)");
  if (n < 1) throw InputError("", "--shard", "'" + text + "': the shard count N must be at least 1");
  if (i >= n)
    throw InputError("", "--shard",
                     "'" + text + "': the shard index I must be below N (shards are numbered 0 to " +
                         std::to_string(n - 1) + ")");
  return Shard{static_cast<int>(i), static_cast<int>(n)};
}

std::vector<bool> shard_membership(const std::vector<std::string>& keys, const Shard& s) {
  std::vector<bool> in(keys.size(), !s.active());
  if (!s.active()) return in;
  std::vector<size_t> order(keys.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::vector<uint64_t> h(keys.size());
  for (size_t k = 0; k < keys.size(); ++k) h[k] = fnv1a64(keys[k]);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return h[a] != h[b] ? h[a] < h[b] : keys[a] < keys[b];
  });
  for (size_t pos = static_cast<size_t>(s.index); pos < order.size(); pos += static_cast<size_t>(s.count))
    in[order[pos]] = true;
  return in;
}

}  // namespace pb
