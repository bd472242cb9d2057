// Shared by the libFuzzer targets (fuzz/fuzz_*.cpp, scripts/fuzz.sh): each
// target writes the input to a file of its own and calls a loader on it, as
// the posebench binary would. A loader may only accept the input or reject
// it with InputError (exit 2 in the binary); any other exception escapes the
// target and libFuzzer reports it, as it reports crashes and sanitizer
// findings.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/error.h"

namespace pbfuzz {

// A folder of this process's own under /tmp (or $TMPDIR), made once.
inline const std::string& work_dir() {
  static const std::string dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("posebench_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d.string();
  }();
  return dir;
}

// Writes the bytes to work_dir()/NAME (replacing it); returns the path.
inline std::string write_file(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = (std::filesystem::path(work_dir()) / name).string();
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) __builtin_trap();
  if (size) std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

inline std::string write_file(const std::string& name, const std::string& text) {
  return write_file(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

// Runs the loader; InputError is a correct answer to bad input.
template <typename F>
void accept_or_reject(F&& load) {
  try {
    load();
  } catch (const pb::InputError&) {
  }
}

}  // namespace pbfuzz
