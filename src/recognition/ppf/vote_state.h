// PPF voting's per-reference state (ppf/voting.cpp only): the vote flags
// and the accumulators. PCL-free.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace pb::ppf {

// Hinterstoisser et al.'s flags for one reference point: per looked-up model
// key (its KeyIndex id) and word of 64 alpha_s bins, a bit per bin already
// voted. Open addressing, emptied per reference by a generation count.
class VoteFlags {
 public:
  // True the first time (id, bin) is seen since the last next_reference().
  bool first(uint32_t id, int bin) {
    if (2 * (used_ + 1) > slots_.size()) grow();
    const uint64_t key = (static_cast<uint64_t>(id) << 32) | (static_cast<uint32_t>(bin) >> 6);
    size_t i = slot(key);
    Slot& s = slots_[i];
    if (s.gen != gen_) {
      s = {key, 0, gen_};
      ++used_;
    }
    const uint64_t m = uint64_t(1) << (static_cast<uint32_t>(bin) & 63);
    if (s.mask & m) return false;
    s.mask |= m;
    return true;
  }
  void next_reference() {
    ++gen_;
    used_ = 0;
  }

 private:
  struct Slot {
    uint64_t key = 0, mask = 0;
    uint32_t gen = 0;
  };
  size_t slot(uint64_t key) const {
    const uint64_t h = (key ^ (key >> 32)) * 0x9e3779b97f4a7c15ull;  // the id is in the high half
    size_t i = static_cast<size_t>(h >> 20) & (slots_.size() - 1);
    while (slots_[i].gen == gen_ && slots_[i].key != key) i = (i + 1) & (slots_.size() - 1);
    return i;
  }
  void grow() {
    std::vector<Slot> old;
    old.swap(slots_);
    slots_.assign(std::max<size_t>(1024, 2 * old.size()), Slot{});
    for (const Slot& s : old)
      if (s.gen == gen_) slots_[slot(s.key)] = s;
  }
  std::vector<Slot> slots_;
  uint32_t gen_ = 1;
  size_t used_ = 0;
};

// The best cell of one reference point's votes, kept as they arrive: the
// most votes, the lowest cell among equals (the first maximum in cell
// order, as a scan of the accumulator finds it, since counts only grow), as
// one maximum of (count, ~cell) packed in 64 bits.
class BestCell {
 public:
  void reset() { packed_ = 0; }
  // Cell `cell` now has `count` votes (count's low 32 bits).
  void offer(uint64_t count, uint32_t cell) {
    packed_ = std::max(packed_, (count << 32) | static_cast<uint32_t>(~cell));
  }
  uint32_t votes() const { return static_cast<uint32_t>(packed_ >> 32); }  // 0: no vote since reset()
  uint32_t cell() const { return ~static_cast<uint32_t>(packed_); }

 private:
  uint64_t packed_ = 0;
};

// Accumulator cells stamped with the reference point that voted for them
// (its generation in the high 32 bits, the count in the low 32): a new
// reference starts from zero without clearing, and a vote needs no branch.
class Accumulator {
 public:
  explicit Accumulator(size_t cells) : cells_(cells, 0) {}
  void next_reference() {
    ++gen_;
    stamp_ = static_cast<uint64_t>(gen_) << 32;
    best_.reset();
  }
  void add(uint32_t cell) {
    const uint64_t v = cells_[cell];
    const uint64_t nv = (v >> 32) == gen_ ? v + 1 : stamp_ + 1;
    cells_[cell] = nv;
    best_.offer(nv, cell);
  }
  const BestCell& best() const { return best_; }

 private:
  std::vector<uint64_t> cells_;
  uint32_t gen_ = 0;
  uint64_t stamp_ = 0;
  BestCell best_;
};

// Accumulator's counts in 16 bits, for a reference point that casts at most
// kMaxVotes votes (the caller's bound: the sum of its pairs' table ranges),
// so no count can overflow: 2 bytes a cell, so that a model's cells stay in
// the first-level cache, cleared after each reference that voted.
class SmallAccumulator {
 public:
  static constexpr uint64_t kMaxVotes = 65535;
  explicit SmallAccumulator(size_t cells) : cells_(cells, 0) {}
  void next_reference() {
    if (best_.votes() != 0) std::fill(cells_.begin(), cells_.end(), uint16_t(0));
    best_.reset();
  }
  void add(uint32_t cell) {
    const uint16_t nv = static_cast<uint16_t>(cells_[cell] + 1);
    cells_[cell] = nv;
    best_.offer(nv, cell);
  }
  const BestCell& best() const { return best_; }

 private:
  std::vector<uint16_t> cells_;
  BestCell best_;
};

}  // namespace pb::ppf
