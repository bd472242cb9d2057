// YAML helpers that make config errors precise: every lookup knows the file,
// and unknown keys are rejected with the file, line and key named. Errors are
// InputError (exit code 2).
#pragma once

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <set>
#include <string>
#include <vector>

#include "core/error.h"

namespace pb {

// A YAML node together with the file it came from and its dotted path.
class YamlNode {
 public:
  // An invalid node (yaml-cpp's "zombie", e.g. a missing key of a const map,
  // whose every type query throws YAML::InvalidNode: found by fuzzing)
  // becomes an undefined one: absent, never an exception.
  YamlNode(YAML::Node node, std::string file, std::string path = "")
      : node_(node.IsDefined() ? std::move(node) : YAML::Node(YAML::NodeType::Undefined)),
        file_(std::move(file)),
        path_(std::move(path)) {}

  // Parses a file; a missing file or a syntax error is an InputError.
  static YamlNode load_file(const std::string& file);
  static YamlNode load_string(const std::string& text, const std::string& name);

  bool has(const std::string& key) const;
  YamlNode operator[](const std::string& key) const;  // child (may be undefined)
  YamlNode at(size_t i) const;
  size_t size() const;
  bool is_map() const { return node_.IsMap(); }
  bool is_sequence() const { return node_.IsSequence(); }
  bool is_scalar() const { return node_.IsScalar(); }
  bool defined() const { return node_.IsDefined() && !node_.IsNull(); }
  std::vector<std::string> keys() const;

  // Rejects any key of this map not in `allowed` (InputError naming file,
  // line and key). Also fails if the node is not a map.
  void check_keys(const std::set<std::string>& allowed) const;

  // Typed reads. `get` throws InputError if absent or of the wrong type;
  // `get_or` returns the fallback when absent. Range helpers check bounds.
  template <typename T>
  T as() const;
  template <typename T>
  T get(const std::string& key) const { return (*this)[key].template as<T>(); }
  template <typename T>
  T get_or(const std::string& key, const T& fallback) const {
    return has(key) ? get<T>(key) : fallback;
  }
  // Reads `key` into `value` if present (keeps the default otherwise).
  template <typename T>
  void read(const std::string& key, T& value) const {
    if (has(key)) value = get<T>(key);
  }
  double get_positive(const std::string& key, double fallback) const;
  double get_nonnegative(const std::string& key, double fallback) const;

  [[noreturn]] void fail(const std::string& what) const;  // InputError at this node
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  int line() const { return node_.Mark().line + 1; }
  const YAML::Node& raw() const { return node_; }
  // This node as JSON, the project's one YAML -> JSON conversion. Scalars
  // are typed as YAML 1.2's core schema reads them: true/false (also True,
  // TRUE, False, FALSE), null (~, null, empty), integers, floats; anything
  // else, and every quoted scalar, is a string. Maps keep their keys,
  // sequences their order. A key given twice in a map (YAML keys are unique;
  // yaml-cpp keeps both) or a key that is not a plain name is an InputError
  // naming this file and the key's path.
  nlohmann::json json() const;

 private:
  YAML::Node node_;
  std::string file_, path_;
};

}  // namespace pb
