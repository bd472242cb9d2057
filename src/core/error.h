// Error types. Bad input (a malformed YAML, a missing mesh, a broken PNG,
// NaN depth...) is an InputError: one message naming the file and the field.
// The CLI turns it into exit code 2.
#pragma once

#include <stdexcept>
#include <string>

namespace pb {

class InputError : public std::runtime_error {
 public:
  // file: the offending file (or "" when not file-based), field: the key,
  // pixel or element that is wrong, what: why it is wrong.
  InputError(const std::string& file, const std::string& field, const std::string& what);
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_, field_;
};

// Exit codes of the posebench binary.
constexpr int kExitOk = 0;
constexpr int kExitFailure = 1;     // an internal error (a bug)
constexpr int kExitInputError = 2;  // bad input: file and field named

}  // namespace pb
