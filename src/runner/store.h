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
  void append(const nlohmann::json& record);  // thread-safe; durable on return
  const std::vector<nlohmann::json>& records() const { return records_; }
  const std::string& dir() const { return dir_; }
  std::string records_path() const;

  // Reads DIR/records.jsonl without opening for writing (the reporter).
  static std::vector<nlohmann::json> read_records(const std::string& dir);

 private:
  std::string dir_;
  std::vector<nlohmann::json> records_;
  std::map<std::string, size_t> index_;
  std::mutex mu_;
};

}  // namespace pb
