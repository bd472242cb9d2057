#include "core/settings_fields.h"

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
