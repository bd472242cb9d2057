// Sharding and merging at the level of functions: the shard assignment
// partitions any key set into N balanced, disjoint parts that depend on the
// keys, not on their order; the merge keeps a finished record over a failed
// one, then the first in source order, flags duplicates whose outcomes
// differ, lists missing trials, and writes canonical trial order.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

#include "core/error.h"
#include "runner/merge.h"
#include "runner/shard.h"
#include "runner/store.h"
#include "runner_test_util.h"

namespace fs = std::filesystem;

namespace {

std::vector<std::string> some_keys(size_t n) {
  std::vector<std::string> keys;
  for (size_t i = 0; i < n; ++i)
    keys.push_back("table/1/" + std::to_string(i / 4) + "/" + std::vector<std::string>{"cvfh", "esf", "shot", "ppf"}[i % 4] +
                   "/icp/{}/noise=0.0");
  return keys;
}

TEST(Shard, PartitionsIntoBalancedDisjointSetsForEveryN) {
  for (size_t count : {size_t{1}, size_t{16}, size_t{97}}) {
    const auto keys = some_keys(count);
    for (int n = 1; n <= 9; ++n) {
      std::vector<int> owner(keys.size(), -1);
      for (int i = 0; i < n; ++i) {
        const auto in = pb::shard_membership(keys, pb::Shard{i, n});
        size_t size = 0;
        for (size_t k = 0; k < keys.size(); ++k)
          if (in[k]) {
            EXPECT_EQ(owner[k], -1) << keys[k] << " in two shards of " << n;
            owner[k] = i;
            ++size;
          }
        EXPECT_GE(size, keys.size() / static_cast<size_t>(n));
        EXPECT_LE(size, (keys.size() + static_cast<size_t>(n) - 1) / static_cast<size_t>(n));
      }
      EXPECT_EQ(std::count(owner.begin(), owner.end(), -1), 0) << "a key in no shard of " << n;
    }
  }
}

TEST(Shard, AssignmentDependsOnTheKeysNotTheirOrder) {
  auto keys = some_keys(40);
  const auto before = pb::shard_membership(keys, pb::Shard{2, 5});
  std::set<std::string> mine;
  for (size_t k = 0; k < keys.size(); ++k)
    if (before[k]) mine.insert(keys[k]);
  std::mt19937 rng(7);
  std::shuffle(keys.begin(), keys.end(), rng);
  const auto after = pb::shard_membership(keys, pb::Shard{2, 5});
  for (size_t k = 0; k < keys.size(); ++k) EXPECT_EQ(after[k], mine.count(keys[k]) == 1) << keys[k];
  // Not a block of consecutive trials: the 8 keys of shard 2/5 are spread
  // over the experiment (heavy and light trials mixed).
  const auto first = some_keys(40);
  const auto in = pb::shard_membership(first, pb::Shard{2, 5});
  std::vector<size_t> pos;
  for (size_t k = 0; k < first.size(); ++k)
    if (in[k]) pos.push_back(k);
  EXPECT_GT(pos.back() - pos.front(), 20u);
}

TEST(Shard, ParsesIAndNAndRejectsTheRest) {
  const pb::Shard s = pb::parse_shard("3/7");
  EXPECT_EQ(s.index, 3);
  EXPECT_EQ(s.count, 7);
  EXPECT_EQ(s.name(), "3-of-7");
  for (const char* bad : {"3/2", "2/2", "0/0", "-1/3", "1", "/3", "1/", "a/3", "1/3x", " 1/3", "1/2/3"})
    EXPECT_THROW(pb::parse_shard(bad), pb::InputError) << bad;
}

using pbtest::record;

struct Folder {
  fs::path dir = fs::temp_directory_path() / ("posebench_merge_" + std::to_string(::getpid()));
  Folder() { fs::remove_all(dir); }
  ~Folder() { fs::remove_all(dir); }
};

TEST(Merge, FinishedBeatsFailedThenSourceOrderAndDifferencesAreReported) {
  Folder f;
  const std::string d = f.dir.string();
  const std::vector<std::string> keys = {"k0", "k1", "k2", "k3", "k4"};
  const nlohmann::json exp = {{"name", "e"}};
  {
    pb::ResultStore a(d, exp, "h", "0-of-2");
    a.append(record("k3", "ok", 0.7));
    a.append(record("k1", "timeout"));  // failed here, finished in 1-of-2
    a.append(record("k0", "ok", 0.1));
  }
  {
    pb::ResultStore b(d, exp, "h", "1-of-2");
    b.append(record("k1", "ok", 0.2));
    b.append(record("k0", "ok", 0.9));  // the same trial, another outcome
  }
  pb::ResultStore::write_trial_list(d, "h", keys);
  const pb::MergeReport rep = pb::merge_results(d);
  EXPECT_EQ(rep.trials, 5u);
  EXPECT_EQ(rep.records, 3u);
  EXPECT_EQ(rep.missing_keys, (std::vector<std::string>{"k2", "k4"}));
  EXPECT_EQ(rep.duplicate_keys, (std::vector<std::string>{"k0", "k1"}));
  EXPECT_EQ(rep.differing_keys, (std::vector<std::string>{"k0"}));
  const auto merged = pb::ResultStore::read_records(d);
  ASSERT_EQ(merged.size(), 3u);
  EXPECT_EQ(merged[0].key, "k0");  // trial order
  EXPECT_EQ(*merged[0].score, 0.1);  // both finished: the first source (shard 0-of-2)
  EXPECT_EQ(merged[1].key, "k1");
  EXPECT_EQ(merged[1].status, "ok");  // finished beats the timeout
  EXPECT_EQ(merged[2].key, "k3");

  // Merging again changes nothing and finds no new duplicates: the merged
  // file's records are the shards' own.
  const std::string text = [&] {
    std::ifstream in(d + "/records.jsonl");
    return std::string(std::istreambuf_iterator<char>(in), {});
  }();
  const pb::MergeReport again = pb::merge_results(d);
  EXPECT_EQ(again.duplicate_keys, rep.duplicate_keys);
  std::ifstream in(d + "/records.jsonl");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), text);
}

TEST(Merge, NeedsTheTrialListAndRefusesWhileARunWrites) {
  Folder f;
  const std::string d = f.dir.string();
  { pb::ResultStore a(d, {{"name", "e"}}, "h", "0-of-1"); }
  EXPECT_THROW(pb::merge_results(d), pb::InputError);  // no trials.json
  pb::ResultStore::write_trial_list(d, "h", {"k0"});
  EXPECT_THROW(pb::merge_results(d, {d + "/no_such_folder"}), pb::InputError);  // not a filesystem_error
  pb::ResultStore::write_trial_list(d, "h", {"k0"});
  pb::ResultStore running(d, {{"name", "e"}}, "h");  // a plain run holding the folder's records
  try {
    pb::merge_results(d);
    FAIL() << "merged while a run writes";
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("another posebench process"), std::string::npos) << e.what();
  }
}

}  // namespace
