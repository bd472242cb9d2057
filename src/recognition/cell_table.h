// Grid cells by open addressing: a cell's key (its integer index triple, or
// one packed integer) -> a number the caller chose when the cell first came
// (linear probing, power-of-two capacity, grown at half load; no allocation
// per cell). The voxel grid (preprocess/voxel_grid.cpp) and the scene's
// Euclidean clusters (global/euclidean.cpp) number their cells with it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pb {

using CellKey = std::array<int64_t, 3>;  // a cell's index along each axis

// The spatial hash of Teschner et al. 2003 (buckets only: nothing's order
// depends on it), and a 64-bit finalizer that folds the high bits in (the
// table masks keep the low ones).
inline uint64_t cell_key_hash(const CellKey& k) {
  return (static_cast<uint64_t>(k[0]) * 73856093u) ^ (static_cast<uint64_t>(k[1]) * 19349663u) ^
         (static_cast<uint64_t>(k[2]) * 83492791u);
}
inline uint64_t cell_key_hash(uint64_t k) { return k; }
template <class K>
inline uint64_t cell_mix(const K& k) {
  uint64_t h = cell_key_hash(k);
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  return h;
}

template <class K>
class CellTable {
 public:
  explicit CellTable(size_t expected) {
    size_t cap = 64;
    while (cap < 2 * expected) cap *= 2;
    keys_.resize(cap);
    slots_.assign(cap, -1);
  }
  // The number of k, `fresh` when k is new (then *inserted = true).
  int find_or_insert(const K& k, int fresh, bool* inserted) {
    if (2 * (size_ + 1) > slots_.size()) grow();
    size_t i = static_cast<size_t>(cell_mix(k)) & (slots_.size() - 1);
    *inserted = false;
    while (slots_[i] >= 0 && !(keys_[i] == k)) i = (i + 1) & (slots_.size() - 1);
    if (slots_[i] < 0) {
      keys_[i] = k;
      slots_[i] = fresh;
      ++size_;
      *inserted = true;
    }
    return slots_[i];
  }
  // The number of k, -1 when it never came.
  int find(const K& k) const {
    for (size_t i = static_cast<size_t>(cell_mix(k)) & (slots_.size() - 1);; i = (i + 1) & (slots_.size() - 1)) {
      if (slots_[i] < 0) return -1;
      if (keys_[i] == k) return slots_[i];
    }
  }

 private:
  void grow() {
    std::vector<K> keys;
    std::vector<int> slots;
    keys.swap(keys_);
    slots.swap(slots_);
    keys_.resize(2 * keys.size());
    slots_.assign(2 * slots.size(), -1);
    for (size_t j = 0; j < slots.size(); ++j) {
      if (slots[j] < 0) continue;
      size_t i = static_cast<size_t>(cell_mix(keys[j])) & (slots_.size() - 1);
      while (slots_[i] >= 0) i = (i + 1) & (slots_.size() - 1);
      keys_[i] = keys[j];
      slots_[i] = slots[j];
    }
  }
  std::vector<K> keys_;
  std::vector<int> slots_;
  size_t size_ = 0;
};

}  // namespace pb
