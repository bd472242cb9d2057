#include "runner/store.h"

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "io/png.h"

namespace fs = std::filesystem;

namespace pb {

std::string ResultStore::records_path() const { return (fs::path(dir_) / "records.jsonl").string(); }

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
  if (!fs::exists(path)) throw InputError(path, "", "no records: not a posebench results folder (run `posebench run` first)");
  size_t valid = 0;
  return parse_records(path, &valid);
}

void ResultStore::check(const std::string& dir, const std::string& hash) {
  const fs::path exp_path = fs::path(dir) / "experiment.json";
  if (fs::exists(exp_path)) {
    std::ifstream in(exp_path);
    nlohmann::json prev;
    try {
      in >> prev;
    } catch (const nlohmann::json::exception&) {
      throw InputError(exp_path.string(), "", "unreadable experiment record; refusing to touch this folder");
    }
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

ResultStore::ResultStore(const std::string& dir, const nlohmann::json& experiment, const std::string& hash)
    : dir_(dir) {
  check(dir, hash);
  const fs::path exp_path = fs::path(dir) / "experiment.json";
  fs::create_directories(dir);
  if (!fs::exists(exp_path)) {
    nlohmann::json e = experiment;
    e["hash"] = hash;
    atomic_write_text(exp_path.string(), e.dump(2) + "\n");
  }
  size_t valid = 0;
  records_ = parse_records(records_path(), &valid);
  if (fs::exists(records_path()) && fs::file_size(records_path()) != valid)
    fs::resize_file(records_path(), valid);  // drop a torn last line
  for (size_t i = 0; i < records_.size(); ++i) index_.emplace(records_[i].key, i);
}

bool ResultStore::has(const std::string& key) const { return index_.count(key) > 0; }

namespace {

// Appends `line` to `path` and flushes it to the disk.
void append_durably(const std::string& path, const std::string& line) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + path + " for appending");
  size_t off = 0;
  while (off < line.size()) {
    const ssize_t n = ::write(fd, line.data() + off, line.size() - off);
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
  append_durably((fs::path(dir_) / "runs.jsonl").string(), run.dump() + "\n");
}

}  // namespace pb
