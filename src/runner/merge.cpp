#include "runner/merge.h"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <unordered_map>

#include "core/error.h"
#include "core/file_lock.h"
#include "runner/store.h"

namespace fs = std::filesystem;

namespace pb {

namespace {

bool finished(const TrialRecord& r) { return r.status == "ok" || r.status == "no_hypothesis"; }

// The record as JSON without the fields that measure time, not outcome, and
// the scene folder's path (shards on several hosts may keep the same scenes
// in different places; the key names the scene).
nlohmann::json outcome(const TrialRecord& r) {
  nlohmann::json j = r;
  for (const char* f : {"wall_s", "train_s", "train_from_cache", "times", "dataset"}) j.erase(f);
  return j;
}

// The hash a shard's header names; InputError if it is missing or unreadable.
std::string shard_header_hash(const std::string& records_file) {
  const std::string suffix = ".records.jsonl";
  const std::string header = records_file.substr(0, records_file.size() - suffix.size()) + ".json";
  std::ifstream in(header);
  if (!in) throw InputError(header, "", "missing: the shard's header (written when the shard starts); cannot tell "
                                        "which experiment " + records_file + " belongs to");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(header, "", std::string("unreadable shard header: ") + e.what());
  }
  if (!j.is_object() || !j.contains("hash") || !j["hash"].is_string())
    throw InputError(header, "hash", "missing in the shard header");
  return j["hash"].get<std::string>();
}

// The record files of one folder, in tie-breaking order, each checked to
// belong to the experiment `hash`.
std::vector<std::string> record_files(const std::string& folder, const std::string& hash) {
  const std::string folder_hash = ResultStore::experiment_hash(folder);
  if (folder_hash != hash)
    throw InputError((fs::path(folder) / "experiment.json").string(), "hash",
                     "records of another experiment (hash " + folder_hash + ", the merge target's is " + hash +
                         "): nothing merged");
  std::vector<std::string> files;
  const std::string main = (fs::path(folder) / "records.jsonl").string();
  if (fs::exists(main)) files.push_back(main);
  for (const auto& f : ResultStore::shard_record_files(folder)) {
    const std::string h = shard_header_hash(f);
    if (h != hash)
      throw InputError(f, "hash", "a shard of another experiment (hash " + h + ", the merge target's is " + hash +
                                      "): nothing merged");
    files.push_back(f);
  }
  return files;
}

// Writes PATH through a temporary file, flushed to the disk before it is
// renamed into place: the merged records replace the old ones whole.
void write_durably(const std::string& path, const std::string& text) {
  const std::string tmp = unique_temp_path(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  bool ok = fd >= 0;
  for (size_t off = 0; ok && off < text.size();) {
    const ssize_t n = ::write(fd, text.data() + off, text.size() - off);
    ok = n > 0;
    if (ok) off += static_cast<size_t>(n);
  }
  ok = ok && ::fsync(fd) == 0;
  if (fd >= 0) ok = ::close(fd) == 0 && ok;
  if (!ok || std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path, "", "cannot write the merged records (disk full? permissions?)");
  }
}

}  // namespace

MergeReport merge_results(const std::string& dir, const std::vector<std::string>& from) {
  const std::string hash = ResultStore::experiment_hash(dir);
  FileLock lock = FileLock::try_acquire(ResultStore::main_lock_path(dir));
  if (!lock.held())
    throw InputError((fs::path(dir) / "records.jsonl").string(), "lock",
                     "another posebench process (a run without --shard, or a merge) is writing it: wait for it");
  const std::vector<std::string> keys = ResultStore::read_trial_list(dir, hash);
  std::unordered_map<std::string, size_t> position;
  for (size_t i = 0; i < keys.size(); ++i) position.emplace(keys[i], i);

  MergeReport rep;
  rep.trials = keys.size();
  std::vector<std::string> files = record_files(dir, hash);
  for (const auto& f : from) {
    std::error_code ec;
    if (!fs::is_directory(f, ec)) throw InputError(f, "", "no such results folder: nothing merged");
    if (fs::equivalent(fs::path(f), fs::path(dir), ec)) continue;
    for (auto& file : record_files(f, hash)) files.push_back(std::move(file));
  }

  std::vector<std::optional<TrialRecord>> chosen(keys.size());
  std::map<size_t, bool> duplicates;  // position -> finished records differ
  for (const auto& file : files) {
    std::vector<TrialRecord> recs = ResultStore::read_file(file);
    rep.sources.push_back({file, recs.size()});
    for (size_t line = 0; line < recs.size(); ++line) {
      TrialRecord& r = recs[line];
      const auto it = position.find(r.key);
      if (it == position.end())
        throw InputError(file, "record " + std::to_string(line + 1) + ": key",
                         "'" + r.key + "' is not a trial of this experiment (" + dir +
                             "/trials.json): nothing merged");
      auto& slot = chosen[it->second];
      if (!slot) {
        slot = std::move(r);
        continue;
      }
      if (nlohmann::json(*slot) == nlohmann::json(r)) continue;  // the same record twice (merged earlier)
      bool& differ = duplicates[it->second];
      if (finished(*slot) && finished(r) && outcome(*slot) != outcome(r)) differ = true;
      if (!finished(*slot) && finished(r)) slot = std::move(r);
    }
  }

  std::string text;
  for (size_t i = 0; i < keys.size(); ++i) {
    if (!chosen[i]) {
      rep.missing_keys.push_back(keys[i]);
      continue;
    }
    text += nlohmann::json(*chosen[i]).dump() + "\n";
    ++rep.records;
  }
  for (const auto& [pos, differ] : duplicates) {
    rep.duplicate_keys.push_back(keys[pos]);
    if (differ) rep.differing_keys.push_back(keys[pos]);
  }
  write_durably((fs::path(dir) / "records.jsonl").string(), text);
  return rep;
}

}  // namespace pb
