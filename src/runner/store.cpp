#include "runner/store.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "core/error.h"
#include "io/png.h"

namespace fs = std::filesystem;

namespace pb {

std::string ResultStore::own_file(const std::string& name, const std::string& suffix) const {
  if (shard_.empty()) return (fs::path(dir_) / (name + "." + suffix)).string();
  return (fs::path(dir_) / "shards" / (shard_ + (name.empty() ? "" : "." + name) + "." + suffix)).string();
}

void ResultStore::write_trial_list(const std::string& dir, const std::string& hash,
                                   const std::vector<std::string>& keys) {
  const std::string path = (fs::path(dir) / "trials.json").string();
  const std::string text = nlohmann::json{{"hash", hash}, {"keys", keys}}.dump(1) + "\n";
  {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    if (in && ss.str() == text) return;  // already there: nothing to rewrite
  }
  atomic_write_text(path, text);
}

std::vector<std::string> ResultStore::read_trial_list(const std::string& dir, const std::string& hash) {
  const std::string path = (fs::path(dir) / "trials.json").string();
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "missing: every `posebench run` writes it; run one (or one shard) first");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "", std::string("unreadable: ") + e.what());
  }
  if (!j.is_object() || !j.contains("hash") || !j["hash"].is_string() || !j.contains("keys") || !j["keys"].is_array())
    throw InputError(path, "keys", "expected {\"hash\": string, \"keys\": [string, ...]}");
  if (j["hash"].get<std::string>() != hash)
    throw InputError(path, "hash", "the trial list of another experiment (hash " + j["hash"].get<std::string>() +
                                       ", experiment.json says " + hash + ")");
  std::vector<std::string> keys;
  for (const auto& k : j["keys"]) {
    if (!k.is_string()) throw InputError(path, "keys", "a key that is not a string");
    keys.push_back(k.get<std::string>());
  }
  return keys;
}

std::string ResultStore::main_lock_path(const std::string& dir) {
  return (fs::path(dir) / ".records.lock").string();
}

std::string ResultStore::records_path() const { return own_file("records", "jsonl"); }

// Parses records.jsonl. Returns the records and the byte length of the valid
// prefix (a torn final line from a killed run is excluded).
static std::vector<TrialRecord> parse_records(const std::string& path, size_t* valid_bytes) {
  std::vector<TrialRecord> out;
  *valid_bytes = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) return out;
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  size_t pos = 0;
  int line_no = 0;
  while (pos < text.size()) {
    const size_t nl = text.find('\n', pos);
    ++line_no;
    if (nl == std::string::npos) break;  // torn last line: no newline yet
    const std::string line = text.substr(pos, nl - pos);
    if (!line.empty()) {
      nlohmann::json j;
      try {
        j = nlohmann::json::parse(line);
      } catch (const nlohmann::json::exception& e) {
        throw InputError(path, "line " + std::to_string(line_no), std::string("corrupt record: ") + e.what());
      }
      out.push_back(record_from_json(j, path, line_no));
    }
    pos = nl + 1;
    *valid_bytes = pos;
  }
  return out;
}

std::vector<TrialRecord> ResultStore::read_records(const std::string& dir) {
  const std::string path = (fs::path(dir) / "records.jsonl").string();
  if (!fs::exists(path)) {
    if (!shard_record_files(dir).empty())
      throw InputError(path, "", "no merged records yet, only shards: run `posebench merge " + dir + "` first");
    throw InputError(path, "", "no records: not a posebench results folder (run `posebench run` first)");
  }
  size_t valid = 0;
  return parse_records(path, &valid);
}

std::vector<TrialRecord> ResultStore::read_file(const std::string& path) {
  size_t valid = 0;
  return parse_records(path, &valid);
}

std::vector<std::string> ResultStore::shard_record_files(const std::string& dir) {
  std::vector<std::pair<std::pair<long, long>, std::string>> found;
  const fs::path shards = fs::path(dir) / "shards";
  std::error_code ec;
  if (!fs::is_directory(shards, ec)) return {};
  const std::string suffix = ".records.jsonl";
  for (const auto& e : fs::directory_iterator(shards)) {
    const std::string name = e.path().filename().string();
    if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    long i = -1, n = -1;
    char tail = 0;
    if (std::sscanf(name.c_str(), "%ld-of-%ld.records.jsonl%c", &i, &n, &tail) != 2) continue;
    found.push_back({{n, i}, e.path().string()});
  }
  std::sort(found.begin(), found.end());
  std::vector<std::string> out;
  for (auto& f : found) out.push_back(std::move(f.second));
  return out;
}

static nlohmann::json read_experiment_json(const fs::path& exp_path) {
  std::ifstream in(exp_path);
  nlohmann::json prev;
  try {
    in >> prev;
  } catch (const nlohmann::json::exception&) {
    throw InputError(exp_path.string(), "", "unreadable experiment record; refusing to touch this folder");
  }
  if (!prev.is_object()) throw InputError(exp_path.string(), "", "not an experiment record; refusing to touch this folder");
  return prev;
}

std::string ResultStore::experiment_hash(const std::string& dir) {
  const fs::path exp_path = fs::path(dir) / "experiment.json";
  if (!fs::exists(exp_path))
    throw InputError(exp_path.string(), "", "missing: not a posebench results folder (run `posebench run` first)");
  const nlohmann::json e = read_experiment_json(exp_path);
  if (!e.contains("hash") || !e["hash"].is_string()) throw InputError(exp_path.string(), "hash", "missing");
  return e["hash"].get<std::string>();
}

void ResultStore::check(const std::string& dir, const std::string& hash) {
  const fs::path exp_path = fs::path(dir) / "experiment.json";
  if (fs::exists(exp_path)) {
    const nlohmann::json prev = read_experiment_json(exp_path);
    const std::string prev_hash = prev.value("hash", "");
    if (prev_hash != hash)
      throw InputError(exp_path.string(), "hash",
                       "this results folder belongs to another experiment ('" + prev.value("name", "?") +
                           "', hash " + prev_hash + "; this one is " + hash +
                           "): choose another --out or remove the folder");
  } else if (fs::exists(fs::path(dir) / "records.jsonl")) {
    throw InputError((fs::path(dir) / "records.jsonl").string(), "",
                     "records without experiment.json: not a folder of this experiment");
  }
}

ResultStore::ResultStore(const std::string& dir, const nlohmann::json& experiment, const std::string& hash,
                         const std::string& shard)
    : dir_(dir), shard_(shard) {
  check(dir, hash);
  const fs::path exp_path = fs::path(dir) / "experiment.json";
  fs::create_directories(shard_.empty() ? fs::path(dir) : fs::path(dir) / "shards");
  const std::string lock_path = shard_.empty() ? main_lock_path(dir) : own_file("", "lock");
  lock_ = FileLock::try_acquire(lock_path);
  if (!lock_.held())
    throw InputError(records_path(), "lock",
                     "another posebench process is writing these records (it holds " + lock_path +
                         "): wait for it to finish or stop it");
  if (!fs::exists(exp_path)) {  // concurrent shards write the same content, each through its own temp file
    nlohmann::json e = experiment;
    e["hash"] = hash;
    atomic_write_text(exp_path.string(), e.dump(2) + "\n");
  }
  if (!shard_.empty())  // the shard's header: what merge checks before taking its records
    atomic_write_text(own_file("", "json"),
                      nlohmann::json{{"experiment", experiment.value("name", "")}, {"hash", hash}, {"shard", shard_}}
                              .dump(2) + "\n");
  size_t valid = 0;
  records_ = parse_records(records_path(), &valid);
  if (fs::exists(records_path()) && fs::file_size(records_path()) != valid)
    fs::resize_file(records_path(), valid);  // drop a torn last line
  for (size_t i = 0; i < records_.size(); ++i) index_.emplace(records_[i].key, i);
}

bool ResultStore::has(const std::string& key) const { return index_.count(key) > 0; }

namespace {

// For testing the runner only (docs/testing.md, "Kills and injected faults"):
// POSEBENCH_TESTING_SLOW_APPEND_MS=N writes each record in two halves with N
// ms between them, so a test can kill the runner in the middle of an append.
long slow_append_ms() {
  static const long ms = [] {
    const char* env = std::getenv("POSEBENCH_TESTING_SLOW_APPEND_MS");
    return env ? std::strtol(env, nullptr, 10) : 0L;
  }();
  return ms;
}

// Appends `line` to `path` and flushes it to the disk.
void append_durably(const std::string& path, const std::string& line) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + path + " for appending");
  size_t off = 0;
  while (off < line.size()) {
    size_t chunk = line.size() - off;
    if (slow_append_ms() > 0 && off == 0 && line.size() > 1) {
      chunk = line.size() / 2;
      ::fdatasync(fd);
    }
    const ssize_t n = ::write(fd, line.data() + off, chunk);
    if (slow_append_ms() > 0 && off == 0 && n > 0) {
      ::fdatasync(fd);
      std::this_thread::sleep_for(std::chrono::milliseconds(slow_append_ms()));
    }
    if (n <= 0) {
      ::close(fd);
      throw std::runtime_error("write failed: " + path);
    }
    off += static_cast<size_t>(n);
  }
  ::fdatasync(fd);
  ::close(fd);
}

}  // namespace

void ResultStore::append(const TrialRecord& record) {
  std::lock_guard<std::mutex> lock(mu_);
  if (index_.count(record.key)) return;
  append_durably(records_path(), nlohmann::json(record).dump() + "\n");
  index_.emplace(record.key, records_.size());
  records_.push_back(record);
}

void ResultStore::append_run(const nlohmann::json& run) const {
  append_durably(own_file("runs", "jsonl"), run.dump() + "\n");
}

}  // namespace pb
