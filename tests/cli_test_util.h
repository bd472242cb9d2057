// Helpers for tests that drive the posebench binary (test_cli_*.cpp).
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace pbcli {

struct Run {
  int code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs `posebench ARGS` in `cwd`, capturing stdout and stderr (through
// files of this process's own, so tests running at once in one cwd, e.g.
// the source tree, never read each other's output).
inline Run run(const std::string& args, const std::string& cwd) {
  static int counter = 0;
  const std::string base = (std::filesystem::temp_directory_path() /
                            ("posebench_cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter++)))
                               .string();
  const std::string o = base + ".stdout", e = base + ".stderr";
  const std::string cmd = "cd '" + cwd + "' && '" + std::string(POSEBENCH_BINARY) + "' " + args + " >'" + o +
                          "' 2>'" + e + "'";
  const int st = std::system(cmd.c_str());
  Run r;
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  r.out = slurp(o);
  r.err = slurp(e);
  std::filesystem::remove(o);
  std::filesystem::remove(e);
  return r;
}

inline void write_file(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream(path) << text;
}

// The records of a records file by key, without the fields that measure
// time (times, wall_s, train_s, train_from_cache); with dataset_name_only,
// `dataset` (the scene folder's path) is cut to the folder's name, the scene
// set's content hash, for runs whose scene folders differ. A key recorded
// twice fails the test.
inline std::map<std::string, nlohmann::json> records_by_key(const std::string& records_file,
                                                            bool dataset_name_only = false) {
  std::map<std::string, nlohmann::json> out;
  std::ifstream in(records_file);
  std::string line;
  while (std::getline(in, line)) {
    auto j = nlohmann::json::parse(line);
    for (const char* k : {"times", "wall_s", "train_s", "train_from_cache"}) j.erase(k);
    if (dataset_name_only) j["dataset"] = std::filesystem::path(j["dataset"].get<std::string>()).filename().string();
    const std::string key = j["key"];
    EXPECT_EQ(out.count(key), 0u) << "duplicate record " << key << " in " << records_file;
    out[key] = j;
  }
  return out;
}

struct TempDir {
  std::string path;
  TempDir() {
    char buf[] = "/tmp/posebench_cli_XXXXXX";
    path = mkdtemp(buf);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

}  // namespace pbcli
