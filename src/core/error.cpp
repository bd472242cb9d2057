#include "core/error.h"

namespace pb {

static std::string compose(const std::string& file, const std::string& field, const std::string& what) {
  std::string s;
  if (!file.empty()) s += file;
  if (!field.empty()) s += (s.empty() ? "" : ": ") + std::string("field '") + field + "'";
  if (!s.empty()) s += ": ";
  return s + what;
}

InputError::InputError(const std::string& file, const std::string& field, const std::string& what)
    : std::runtime_error(compose(file, field, what)), file_(file), field_(field) {}

}  // namespace pb
