// One list of fields per settings struct, from which the YAML parser (with
// unknown keys rejected), the key list and the JSON form all derive, so a
// field is declared once (with its comment) and listed once:
//
//   struct PreprocessSettings {
//     double voxel_mm = 10.0;  // downsampling voxel
//     template <class S, class F> static void fields(S& s, F& f) {
//       f("voxel_mm", s.voxel_mm, fields::nonnegative());
//     }
//     void validate(const YamlNode& node) const;  // optional: checks across fields
//   };
//
//   parse_section(node, settings);      // YAML section -> struct
//   section_json(settings);             // struct -> ordered JSON (records, cache keys)
//
// The rules give the messages the project's parsers always gave ("must be
// positive, got -3", "must be in [0, 1]", ...), with file, line and key
// through YamlNode::fail.
//
// A field may also be a nested section, a settings struct of its own under
// a key of the parent's YAML section (`refine: {ndt: {resolution_mm: 30}}`):
// `f.section("ndt", s.ndt)` in the parent's fields list. Every visitor has
// a section(key, sub) member; keys inside it are "PARENT.key.field" in the
// relative map and in messages.
//
// A length field (rule wrapped in fields::length) may also be given as a
// fraction of the object's diameter, `voxel_mm: 0.05d`, when the caller
// passes a `relative` map: the fraction is kept there under "PREFIX.key" and
// the field's number is left as it is until the caller resolves it (see
// recognition/settings.h, resolve_lengths); a number given in mm removes the
// entry. The JSON form writes such a field back as "0.05d".
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "core/yaml.h"

namespace pb {
namespace fields {

struct Rule {
  enum Kind { kAny, kPositive, kNonnegative, kAtLeast, kRange, kOneOf } kind = kAny;
  double lo = 0, hi = 0;
  std::vector<std::string> names;  // kOneOf
  double max = 0;                  // > 0: also "must be at most max" (kPositive, kNonnegative)
  std::string unit;                // appended to "at most" messages, e.g. " degrees"
  bool length = false;             // a length: may be a fraction of the diameter ("0.05d")
};

inline Rule any() { return {}; }
inline Rule positive(double max = 0, std::string unit = "") { return {Rule::kPositive, 0, 0, {}, max, unit}; }
inline Rule nonnegative(double max = 0, std::string unit = "") {
  return {Rule::kNonnegative, 0, 0, {}, max, unit};
}
inline Rule at_least(double lo, double max = 0) { return {Rule::kAtLeast, lo, 0, {}, max, ""}; }
inline Rule in_range(double lo, double hi) { return {Rule::kRange, lo, hi, {}, 0, ""}; }
inline Rule one_of(std::vector<std::string> names) { return {Rule::kOneOf, 0, 0, std::move(names), 0, ""}; }
// A length in mm that may also be written as a fraction of the diameter.
inline Rule length(Rule r) {
  r.length = true;
  return r;
}

// "0.05d" -> 0.05; false when `text` is not of that form. A form with a
// fraction that is not a positive finite number fails at `node`.
bool parse_relative(const YamlNode& node, const std::string& text, double* fraction);
// 0.05 -> "0.05d" (shortest round-trip form).
std::string relative_text(double fraction);

// What a rule accepts, in words: "> 0", ">= 0 and <= 90 degrees", "in [0, 1]",
// "one of: view, merged"; a length adds "(mm, or a fraction of the
// diameter: 0.05d)". Empty for any value.
std::string rule_text(const Rule& r);

// Checks a read value; fails at `node` (the field's node).
void check(const YamlNode& node, double v, const Rule& r);
void check(const YamlNode& node, const std::string& v, const Rule& r);

// A visitor with a `prefix` member visits a nested section as a copy of
// itself with the prefix extended by "key.".
template <typename V, typename Sub>
void nested(const V& v, const char* key, Sub& sub) {
  V inner = v;
  inner.prefix = v.prefix + key + ".";
  std::decay_t<Sub>::fields(sub, inner);
}

struct KeyLister {
  std::set<std::string> keys;
  template <typename T>
  void operator()(const char* key, const T&, const Rule& = {}) {
    keys.insert(key);
  }
  template <typename Sub>
  void section(const char* key, const Sub&) {
    keys.insert(key);
  }
};

struct Reader {
  const YamlNode& node;
  std::map<std::string, double>* relative = nullptr;  // "PREFIX.key" -> fraction (length fields)
  std::string prefix;
  std::set<std::string>* given_relative = nullptr;    // the keys this section gave as fractions
  template <typename T>
  void operator()(const char* key, T& v, const Rule& r = {}) {
    if (!node.has(key)) return;
    const YamlNode n = node[key];
    if constexpr (std::is_floating_point_v<T>) {
      if (r.length && relative) {
        double fraction = 0;
        if (parse_relative(n, n.as<std::string>(), &fraction)) {
          (*relative)[prefix + key] = fraction;
          if (given_relative) given_relative->insert(prefix + key);
          return;
        }
        relative->erase(prefix + key);
      }
    }
    if constexpr (std::is_same_v<T, bool>) {
      v = n.as<bool>();
    } else if constexpr (std::is_same_v<T, std::string>) {
      v = n.as<std::string>();
      check(n, v, r);
    } else if constexpr (std::is_integral_v<T>) {
      v = n.as<T>();
      check(n, static_cast<double>(v), r);
    } else {
      v = n.as<T>();
      check(n, static_cast<double>(v), r);
    }
  }
  template <typename Sub>
  void section(const char* key, Sub& sub);  // parse_section of node[key], below
};

struct JsonWriter {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  const std::map<std::string, double>* relative = nullptr;
  std::string prefix;
  template <typename T>
  void operator()(const char* key, const T& v, const Rule& = {}) {
    if (relative) {
      const auto it = relative->find(prefix + key);
      if (it != relative->end()) {
        j[key] = relative_text(it->second);
        return;
      }
    }
    j[key] = v;
  }
  template <typename Sub>
  void section(const char* key, const Sub& sub) {
    JsonWriter inner{nlohmann::ordered_json::object(), relative, prefix + key + "."};
    Sub::fields(sub, inner);
    j[key] = std::move(inner.j);
  }
};

// Every field's key, type, default and rule_text: the settings reference
// (`posebench schema settings`, docs/settings.md).
struct SchemaWriter {
  nlohmann::ordered_json fields = nlohmann::ordered_json::array();
  nlohmann::ordered_json sections = nlohmann::ordered_json::array();  // nested: {name, fields}, names
                                                                       // "key" or "key.inner"
  const std::map<std::string, double>* relative = nullptr;  // defaults given as fractions
  std::string prefix;
  template <typename T>
  void operator()(const char* key, const T& v, const Rule& r = {}) {
    nlohmann::ordered_json f;
    f["key"] = key;
    if constexpr (std::is_same_v<T, bool>) f["type"] = "bool";
    else if constexpr (std::is_same_v<T, std::string>) f["type"] = "string";
    else if constexpr (std::is_integral_v<T>) f["type"] = "integer";
    else f["type"] = "number";
    if (relative && relative->count(prefix + key)) f["default"] = relative_text(relative->at(prefix + key));
    else f["default"] = v;
    f["accepts"] = rule_text(r);
    fields.push_back(std::move(f));
  }
  template <typename Sub>
  void section(const char* key, const Sub& sub) {
    SchemaWriter inner;
    inner.relative = relative;
    inner.prefix = prefix + key + ".";
    Sub::fields(sub, inner);
    sections.push_back({{"name", key}, {"fields", std::move(inner.fields)}});
    for (auto& s : inner.sections) {
      s["name"] = std::string(key) + "." + s["name"].get<std::string>();
      sections.push_back(std::move(s));
    }
  }
};

template <typename S, typename = void>
struct has_validate : std::false_type {};
template <typename S>
struct has_validate<S, std::void_t<decltype(std::declval<const S&>().validate(std::declval<const YamlNode&>()))>>
    : std::true_type {};

}  // namespace fields

// Reads a YAML section over `s` (fields not given keep their values).
// `relative` (optional): where length fields given as "0.05d" go, under
// "PREFIX.key" (see fields::length).
// `given_relative` (optional) collects the keys given as fractions here.
template <typename S>
void parse_section(const YamlNode& node, S& s, std::map<std::string, double>* relative = nullptr,
                   const std::string& prefix = "", std::set<std::string>* given_relative = nullptr) {
  if (!node.defined()) return;
  fields::KeyLister keys;
  S::fields(s, keys);
  node.check_keys(keys.keys);
  fields::Reader reader{node, relative, prefix, given_relative};
  S::fields(s, reader);
  if constexpr (fields::has_validate<S>::value) s.validate(node);
}

// Every field, in declaration order; fields in `relative` as "0.05d".
template <typename Sub>
void fields::Reader::section(const char* key, Sub& sub) {
  if (node.has(key)) parse_section(node[key], sub, relative, prefix + key + ".", given_relative);
}

template <typename S>
nlohmann::ordered_json section_json(const S& s, const std::map<std::string, double>* relative = nullptr,
                                    const std::string& prefix = "") {
  fields::JsonWriter w;
  w.relative = relative;
  w.prefix = prefix;
  S::fields(s, w);
  return std::move(w.j);
}

template <typename S>
std::set<std::string> section_keys() {
  S s;
  fields::KeyLister keys;
  S::fields(s, keys);
  return keys.keys;
}

}  // namespace pb
