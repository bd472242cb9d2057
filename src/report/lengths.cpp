#include "report/lengths.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <set>
#include <sstream>

namespace pb {

namespace {

constexpr const char* kSections[] = {"preprocess", "local", "global", "ppf", "refine", "verify"};

std::string mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

std::vector<ResolvedLengths> resolved_lengths(const std::vector<TrialRecord>& records) {
  std::vector<ResolvedLengths> out;
  std::map<std::string, size_t> index;
  for (const auto& r : records) {
    if (!r.settings_resolved || !r.settings_resolved->is_object()) continue;
    const nlohmann::json& s = *r.settings_resolved;
    const std::string group = r.scene + ", obj " + (r.obj_id ? std::to_string(*r.obj_id) : std::string("?"));
    auto [it, fresh] = index.emplace(group, out.size());
    if (fresh) out.push_back({group, {}});
    auto& range = out[it->second].range_mm;
    auto add = [&](const std::string& key, const nlohmann::json& v) {
      if (!v.is_number()) return;
      const double x = v.get<double>();
      if (!(x >= 0)) return;
      auto [r_it, first] = range.emplace(key, std::make_pair(x, x));
      if (!first) r_it->second = {std::min(r_it->second.first, x), std::max(r_it->second.second, x)};
    };
    for (const char* section : kSections) {
      if (!s.contains(section) || !s[section].is_object()) continue;
      // The section's *_mm fields and those of its nested sections (refine.ndt).
      std::function<void(const std::string&, const nlohmann::json&)> lengths = [&](const std::string& prefix,
                                                                                   const nlohmann::json& obj) {
        for (auto f = obj.begin(); f != obj.end(); ++f) {
          const std::string& k = f.key();
          if (f.value().is_object()) lengths(prefix + k + ".", f.value());
          else if (k.size() > 3 && k.compare(k.size() - 3, 3, "_mm") == 0) add(prefix + k, f.value());
        }
      };
      lengths(std::string(section) + ".", s[section]);
    }
    if (s.contains("scale") && s["scale"].is_object() && s["scale"].contains("min_length_mm"))
      add("scale.min_length_mm", s["scale"]["min_length_mm"]);
  }
  return out;
}

std::string resolved_lengths_markdown(const std::vector<ResolvedLengths>& groups) {
  if (groups.empty()) return "";
  std::set<std::string> keys;
  for (const auto& g : groups)
    for (const auto& [k, v] : g.range_mm) keys.insert(k);
  std::ostringstream o;
  o << "### Lengths as resolved (mm)\n\n| setting |";
  for (const auto& g : groups) o << " " << g.group << " |";
  o << "\n|---|";
  for (size_t i = 0; i < groups.size(); ++i) o << "---|";
  o << "\n";
  for (const auto& k : keys) {
    o << "| " << k << " |";
    for (const auto& g : groups) {
      const auto it = g.range_mm.find(k);
      if (it == g.range_mm.end())
        o << " - |";
      else if (it->second.first == it->second.second)
        o << " " << mm(it->second.first) << " |";
      else
        o << " " << mm(it->second.first) << "-" << mm(it->second.second) << " |";
    }
    o << "\n";
  }
  o << "\nEach record's settings_resolved has the values of its trial.\n\n";
  return o.str();
}

}  // namespace pb
