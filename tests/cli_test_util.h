// Helpers for tests that drive the posebench binary (test_cli_*.cpp).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
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

// Runs `posebench ARGS` in `cwd`, capturing stdout and stderr.
inline Run run(const std::string& args, const std::string& cwd) {
  const std::string o = cwd + "/.stdout", e = cwd + "/.stderr";
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
