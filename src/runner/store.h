// The results folder of an experiment: experiment.json (the canonical config
// and its hash) and records.jsonl (one JSON record per finished trial,
// appended and flushed as each trial finishes). Killing a run loses nothing
// that finished: a torn last line is dropped on the next open, and a resumed
// run skips every key already recorded.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "eval/record.h"

namespace pb {

class ResultStore {
 public:
  // Opens (creating) DIR. If DIR/experiment.json exists with another hash,
  // throws InputError naming it and leaves everything untouched.
  ResultStore(const std::string& dir, const nlohmann::json& experiment, const std::string& hash);

  // The guard alone, read-only: throws the same InputError as the
  // constructor if DIR belongs to another experiment; creates nothing.
  static void check(const std::string& dir, const std::string& hash);

  bool has(const std::string& key) const;
  size_t size() const { return records_.size(); }
  void append(const TrialRecord& record);  // thread-safe; durable on return
  const std::vector<TrialRecord>& records() const { return records_; }
  const std::string& dir() const { return dir_; }
  std::string records_path() const;

  // Reads DIR/records.jsonl without opening for writing (the reporter).
  // Strict: a record with an unknown or missing key is an InputError naming
  // the file, the line and the key.
  static std::vector<TrialRecord> read_records(const std::string& dir);

  // Appends one line to DIR/runs.jsonl (one per `posebench run` invocation
  // that ran trials).
  void append_run(const nlohmann::json& run) const;

 private:
  std::string dir_;
  std::vector<TrialRecord> records_;
  std::map<std::string, size_t> index_;
  std::mutex mu_;
};

}  // namespace pb
