// Small helpers shared by bop.cpp and bop_dataset.cpp (not an interface).
#pragma once

#include <algorithm>
#include <filesystem>
#include <string>

namespace pb::bop_detail {

inline bool is_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

inline std::string join_path(const std::string& a, const std::string& b) {
  return (std::filesystem::path(a) / b).string();
}

}  // namespace pb::bop_detail
