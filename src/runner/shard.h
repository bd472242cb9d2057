// Sharding a run over independent processes or cluster tasks (`run --shard
// I/N`, Slurm job arrays): which trials shard I of N runs. PCL-free.
//
// The assignment depends only on the experiment's trial keys: the keys are
// ordered by their FNV-1a hash (then by the key itself) and shard I takes
// positions I, I + N, I + 2N, ... of that order. So the N shards split the
// trials into disjoint sets of equal size (within one), heavy and light
// trials mixed at random, and a shard rerun alone, or run while the others
// run, gets exactly the same trials.
#pragma once

#include <string>
#include <vector>

namespace pb {

struct Shard {
  int index = 0;  // I: 0 .. count - 1 (Slurm's SLURM_ARRAY_TASK_ID with --array=0-(N-1))
  int count = 0;  // N; 0 = not sharded (every trial)
  bool active() const { return count > 0; }
  std::string name() const;   // "I-of-N": the file names under DIR/shards/
  std::string label() const;  // "I/N"
};

// Parses "I/N" (0 <= I < N, both integers). InputError naming --shard and
// what is wrong (e.g. "3/2": index 3 is not below the count 2).
Shard parse_shard(const std::string& text);

// For each key, whether shard `s` runs it (all true when !s.active()).
std::vector<bool> shard_membership(const std::vector<std::string>& keys, const Shard& s);

}  // namespace pb
