// Helpers for tests that drive the posebench binary (test_cli_*.cpp).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

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
