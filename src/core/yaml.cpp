#include "core/yaml.h"

#include <algorithm>
#include <cstdio>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

namespace pb {

YamlNode YamlNode::load_file(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "", "cannot open file");
  std::stringstream ss;
  ss << in.rdbuf();
  return load_string(ss.str(), file);
}

namespace {

// The byte offset of the first byte that breaks UTF-8 (RFC 3629: no overlong
// forms, no surrogates, nothing above U+10FFFF), or npos. YAML text is
// Unicode; yaml-cpp passes any bytes on, and they broke JSON output later.
size_t invalid_utf8_at(const std::string& s) {
  size_t i = 0;
  const size_t n = s.size();
  while (i < n) {
    const auto c = static_cast<unsigned char>(s[i]);
    int len = 0;
    unsigned cp = 0;
    if (c < 0x80) len = 1, cp = c;
    else if (c >= 0xc2 && c <= 0xdf) len = 2, cp = c & 0x1fu;
    else if (c >= 0xe0 && c <= 0xef) len = 3, cp = c & 0x0fu;
    else if (c >= 0xf0 && c <= 0xf4) len = 4, cp = c & 0x07u;
    else return i;
    if (i + static_cast<size_t>(len) > n) return i;
    for (int k = 1; k < len; ++k) {
      const auto d = static_cast<unsigned char>(s[i + static_cast<size_t>(k)]);
      if ((d & 0xc0u) != 0x80u) return i;
      cp = (cp << 6) | (d & 0x3fu);
    }
    if ((len == 3 && (cp < 0x800 || (cp >= 0xd800 && cp <= 0xdfff))) || (len == 4 && (cp < 0x10000 || cp > 0x10ffff)))
      return i;
    i += static_cast<size_t>(len);
  }
  return std::string::npos;
}

// The byte offset of the first character YAML does not allow in a stream
// (YAML 1.2 c-printable: no C0 control but tab, LF and CR, no DEL, no C1
// control but NEL, no U+FFFE / U+FFFF), in text that is valid UTF-8.
// yaml-cpp turned a NUL byte into bytes that are not UTF-8 (found by
// fuzzing: the experiment's JSON dump then threw).
size_t unprintable_at(const std::string& s) {
  for (size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f) return i;
    if (c == 0xc2 && i + 1 < s.size()) {  // U+0080..U+009F: C1 controls, NEL (U+0085) allowed
      const auto d = static_cast<unsigned char>(s[i + 1]);
      if (d >= 0x80 && d <= 0x9f && d != 0x85) return i;
    }
    if (c == 0xef && i + 2 < s.size() && static_cast<unsigned char>(s[i + 1]) == 0xbf &&
        static_cast<unsigned char>(s[i + 2]) >= 0xbe)  // U+FFFE, U+FFFF
      return i;
  }
  return std::string::npos;
}

size_t line_of(const std::string& text, size_t at) {
  return 1 + static_cast<size_t>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

}  // namespace

YamlNode YamlNode::load_string(const std::string& text, const std::string& name) {
  if (const size_t bad = invalid_utf8_at(text); bad != std::string::npos)
    throw InputError(name, "", "not UTF-8 text: line " + std::to_string(line_of(text, bad)) + ", byte " + std::to_string(bad));
  if (const size_t bad = unprintable_at(text); bad != std::string::npos) {
    char code[8];
    std::snprintf(code, sizeof code, "0x%02x", static_cast<unsigned char>(text[bad]));
    throw InputError(name, "", "a control character (" + std::string(code) + ") YAML does not allow: line " +
                                   std::to_string(line_of(text, bad)) + ", byte " + std::to_string(bad));
  }
  try {
    YAML::Node n = YAML::Load(text);
    if (!n.IsDefined() || n.IsNull()) n = YAML::Node(YAML::NodeType::Map);
    return YamlNode(n, name);
  } catch (const YAML::Exception& e) {
    throw InputError(name, "", "malformed YAML at line " + std::to_string(e.mark.line + 1) +
                                   ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

bool YamlNode::has(const std::string& key) const {
  return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
}

YamlNode YamlNode::operator[](const std::string& key) const {
  const std::string p = path_.empty() ? key : path_ + "." + key;
  if (!node_.IsMap()) return YamlNode(YAML::Node(), file_, p);
  return YamlNode(node_[key], file_, p);
}

YamlNode YamlNode::at(size_t i) const {
  const std::string p = path_ + "[" + std::to_string(i) + "]";
  if (!node_.IsSequence() || i >= node_.size()) fail("index " + std::to_string(i) + " out of range");
  return YamlNode(node_[i], file_, p);
}

size_t YamlNode::size() const { return node_.IsSequence() || node_.IsMap() ? node_.size() : 0; }

// A mapping key as text; a key that is not a plain scalar ("? [1, 2]",
// found by fuzzing: yaml-cpp threw BadConversion) is an InputError.
static std::string key_text(const YAML::Node& key, const std::string& file, const std::string& path) {
  if (!key.IsScalar())
    throw InputError(file, path,
                     "a key must be a plain name (line " + std::to_string(key.Mark().line + 1) + ")");
  return key.Scalar();
}

// Records `key` (at `line`) as seen in one mapping; a key seen before is an
// InputError: YAML keys are unique, yaml-cpp keeps every copy and its
// lookups return the first.
static void check_unique_key(std::map<std::string, int>& seen, const std::string& key, int line,
                             const std::string& file, const std::string& path) {
  if (const auto [it, fresh] = seen.emplace(key, line); !fresh)
    throw InputError(file, path.empty() ? key : path + "." + key,
                     "key given twice, at lines " + std::to_string(it->second) + " and " + std::to_string(line));
}

std::vector<std::string> YamlNode::keys() const {
  std::vector<std::string> k;
  if (node_.IsMap())
    for (const auto& kv : node_) k.push_back(key_text(kv.first, file_, path_));
  return k;
}

void YamlNode::check_keys(const std::set<std::string>& allowed) const {
  if (!defined()) return;
  if (!node_.IsMap()) fail("expected a mapping");
  std::map<std::string, int> seen;
  for (const auto& kv : node_) {
    const std::string key = key_text(kv.first, file_, path_);
    check_unique_key(seen, key, kv.first.Mark().line + 1, file_, path_);
    if (!allowed.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      const std::string p = path_.empty() ? key : path_ + "." + key;
      throw InputError(file_, p,
                       "unknown key at line " + std::to_string(kv.first.Mark().line + 1) +
                           " (allowed: " + list + ")");
    }
  }
}

void YamlNode::fail(const std::string& what) const {
  std::string w = what;
  if (node_.IsDefined() && node_.Mark().line >= 0) w += " (line " + std::to_string(line()) + ")";
  throw InputError(file_, path_, w);
}

template <typename T>
T YamlNode::as() const {
  if (!node_.IsDefined() || node_.IsNull()) fail("missing value");
  try {
    return node_.as<T>();
  } catch (const YAML::Exception&) {
    fail("wrong type or malformed value '" + (node_.IsScalar() ? node_.Scalar() : std::string("<non-scalar>")) + "'");
  }
}

template int YamlNode::as<int>() const;
template unsigned YamlNode::as<unsigned>() const;
template long YamlNode::as<long>() const;
template unsigned long YamlNode::as<unsigned long>() const;
template long long YamlNode::as<long long>() const;
template unsigned long long YamlNode::as<unsigned long long>() const;
template double YamlNode::as<double>() const;
template float YamlNode::as<float>() const;
template bool YamlNode::as<bool>() const;
template std::string YamlNode::as<std::string>() const;
template std::vector<double> YamlNode::as<std::vector<double>>() const;
template std::vector<int> YamlNode::as<std::vector<int>>() const;
template std::vector<std::string> YamlNode::as<std::vector<std::string>>() const;

double YamlNode::get_positive(const std::string& key, double fallback) const {
  const double v = get_or<double>(key, fallback);
  if (!(v > 0)) (*this)[key].fail("must be positive, got " + std::to_string(v));
  return v;
}

double YamlNode::get_nonnegative(const std::string& key, double fallback) const {
  const double v = get_or<double>(key, fallback);
  if (!(v >= 0)) (*this)[key].fail("must be non-negative, got " + std::to_string(v));
  return v;
}

static nlohmann::json to_json(const YAML::Node& n, const std::string& file, const std::string& path) {
  if (n.IsMap()) {
    nlohmann::json j = nlohmann::json::object();
    std::map<std::string, int> seen;
    for (const auto& kv : n) {
      const std::string key = key_text(kv.first, file, path);
      check_unique_key(seen, key, kv.first.Mark().line + 1, file, path);
      j[key] = to_json(kv.second, file, path.empty() ? key : path + "." + key);
    }
    return j;
  }
  if (n.IsSequence()) {
    nlohmann::json j = nlohmann::json::array();
    size_t i = 0;
    for (const auto& e : n) j.push_back(to_json(e, file, path + "[" + std::to_string(i++) + "]"));
    return j;
  }
  if (!n.IsDefined() || n.IsNull()) return nullptr;
  const std::string s = n.Scalar();
  if (n.Tag() == "!") return s;  // quoted
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  if (s.empty()) return s;
  char* end = nullptr;
  errno = 0;
  const long long iv = std::strtoll(s.c_str(), &end, 10);
  if (*end == '\0' && errno == 0) return iv;
  const double dv = std::strtod(s.c_str(), &end);
  if (*end == '\0') return dv;
  return s;
}

nlohmann::json YamlNode::json() const { return to_json(node_, file_, path_); }

}  // namespace pb
