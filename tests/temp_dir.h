// A temporary folder for one test, removed with everything in it when the
// test is done: TempDir tmp("mesh"); tmp / "a.ply" is a path inside it.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <string>

namespace pbtest {

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& tag = "test") {
    std::string tmpl = (std::filesystem::temp_directory_path() / ("pb_test_" + tag + "_XXXXXX")).string();
    path = mkdtemp(tmpl.data());
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string operator/(const std::string& f) const { return (path / f).string(); }
};

}  // namespace pbtest
