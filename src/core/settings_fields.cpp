#include "core/settings_fields.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace pb::fields {

namespace {

std::string num(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

void check(const YamlNode& node, double v, const Rule& r) {
  switch (r.kind) {
    case Rule::kAny:
    case Rule::kOneOf:
      break;
    case Rule::kPositive:
      if (!(v > 0)) node.fail("must be positive, got " + std::to_string(v));
      break;
    case Rule::kNonnegative:
      if (!(v >= 0)) node.fail("must be non-negative, got " + std::to_string(v));
      break;
    case Rule::kAtLeast:
      if (!(v >= r.lo)) node.fail("must be at least " + num(r.lo) + ", got " + num(v));
      break;
    case Rule::kRange:
      if (!(v >= r.lo && v <= r.hi)) node.fail("must be in [" + num(r.lo) + ", " + num(r.hi) + "], got " + num(v));
      break;
  }
  if (r.max > 0 && v > r.max) node.fail("must be at most " + num(r.max) + r.unit + ", got " + num(v));
}

std::string rule_text(const Rule& r) {
  std::string t;
  switch (r.kind) {
    case Rule::kAny: break;
    case Rule::kPositive: t = "> 0"; break;
    case Rule::kNonnegative: t = ">= 0"; break;
    case Rule::kAtLeast: t = ">= " + num(r.lo); break;
    case Rule::kRange: t = "in [" + num(r.lo) + ", " + num(r.hi) + "]"; break;
    case Rule::kOneOf:
      t = "one of:";
      for (size_t i = 0; i < r.names.size(); ++i) t += (i ? ", " : " ") + r.names[i];
      break;
  }
  if (r.max > 0) t += (t.empty() ? "" : ", ") + std::string("<= ") + num(r.max) + r.unit;
  if (r.length) t += (t.empty() ? "" : " ") + std::string("(mm, or a fraction of the diameter: 0.05d)");
  return t;
}

bool parse_relative(const YamlNode& node, const std::string& text, double* fraction) {
  if (text.size() < 2 || text.back() != 'd') return false;
  const std::string number = text.substr(0, text.size() - 1);
  char* end = nullptr;
  const double f = std::strtod(number.c_str(), &end);
  if (end != number.c_str() + number.size() || number.find_first_of(" \t") != std::string::npos)
    return false;
  if (!(f > 0) || !std::isfinite(f))
    node.fail("a length relative to the object's diameter must be a positive fraction followed by d (e.g. "
              "0.05d), got '" + text + "'");
  *fraction = f;
  return true;
}

std::string relative_text(double fraction) { return nlohmann::json(fraction).dump() + "d"; }

void check(const YamlNode& node, const std::string& v, const Rule& r) {
  if (r.kind != Rule::kOneOf) return;
  for (const auto& n : r.names)
    if (v == n) return;
  std::string list;
  for (size_t i = 0; i < r.names.size(); ++i)
    list += (i == 0 ? "'" : (i + 1 == r.names.size() ? " or '" : ", '")) + r.names[i] + "'";
  node.fail("must be " + list + ", got '" + v + "'");
}

}  // namespace pb::fields
