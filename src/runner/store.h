// The results folder of an experiment: experiment.json (the canonical config
// and its hash), trials.json (every trial key in canonical order) and
// records.jsonl (one JSON record per finished trial, appended and flushed as
// each trial finishes). Killing a run loses nothing that finished: a torn
// last line is dropped on the next open, and a resumed run skips every key
// already recorded.
//
// A sharded run (`run --shard I/N`, runner/shard.h) writes its own files
// under DIR/shards/, named I-of-N: .records.jsonl, .json (its header: the
// experiment hash, I, N, host), .runs.jsonl, .workers.log. No two writers
// share a file: each holds an exclusive lock (DIR/.records.lock or
// DIR/shards/I-of-N.lock) while it writes. `posebench merge` (runner/merge.h)
// merges the shards into DIR/records.jsonl.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "core/file_lock.h"
#include "eval/record.h"

namespace pb {

class ResultStore {
 public:
  // Opens (creating) DIR for writing DIR/records.jsonl, or, with a shard
  // name ("I-of-N"), DIR/shards/I-of-N.records.jsonl. If DIR/experiment.json
  // exists with another hash, throws InputError naming it and leaves
  // everything untouched; likewise if another process holds the writer's
  // lock (the same run or shard started twice).
  ResultStore(const std::string& dir, const nlohmann::json& experiment, const std::string& hash,
              const std::string& shard = "");

  // The hash in DIR/experiment.json; InputError if it is missing or unreadable.
  static std::string experiment_hash(const std::string& dir);

  // The guard alone, read-only: throws the same InputError as the
  // constructor if DIR belongs to another experiment; creates nothing.
  static void check(const std::string& dir, const std::string& hash);

  bool has(const std::string& key) const;
  size_t size() const { return records_.size(); }
  void append(const TrialRecord& record);  // thread-safe; durable on return
  const std::vector<TrialRecord>& records() const { return records_; }
  const std::string& dir() const { return dir_; }
  std::string records_path() const;
  // This writer's file: DIR/NAME.SUFFIX, or DIR/shards/I-of-N.NAME.SUFFIX
  // for a shard (I-of-N.SUFFIX when NAME is empty).
  std::string own_file(const std::string& name, const std::string& suffix) const;

  // Reads DIR/records.jsonl without opening for writing (the reporter).
  // Strict: a record with an unknown or missing key is an InputError naming
  // the file, the line and the key.
  static std::vector<TrialRecord> read_records(const std::string& dir);

  // The complete records of one records file (a torn last line, still being
  // written or left by a kill, is skipped; the file is not modified).
  // Strict as read_records. An absent file has none.
  static std::vector<TrialRecord> read_file(const std::string& path);

  // DIR/trials.json: {"hash", "keys": every trial key in canonical order},
  // written by every run (atomically; concurrent shards write the same
  // content) and read by merge. read_trial_list throws InputError if it is
  // missing, unreadable or of another hash.
  static void write_trial_list(const std::string& dir, const std::string& hash, const std::vector<std::string>& keys);
  static std::vector<std::string> read_trial_list(const std::string& dir, const std::string& hash);

  // The lock a writer of DIR/records.jsonl holds (a run without --shard, a merge).
  static std::string main_lock_path(const std::string& dir);

  // DIR/shards/*.records.jsonl, ordered by (N, I).
  static std::vector<std::string> shard_record_files(const std::string& dir);

  // Appends one line to DIR/runs.jsonl (one per `posebench run` invocation
  // that ran trials).
  void append_run(const nlohmann::json& run) const;

 private:
  std::string dir_, shard_;
  FileLock lock_;
  std::vector<TrialRecord> records_;
  std::map<std::string, size_t> index_;
  std::mutex mu_;
};

}  // namespace pb
