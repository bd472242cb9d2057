// Real against twin, target by target (twin_gap.h).
#include "report/twin_gap.h"

#include <cstdio>
#include <map>
#include <tuple>

namespace pb {

namespace {

bool found(const TrialRecord& r) {
  if (!r.bop || r.bop->diameter <= 0) return false;
  return r.bop->mssd_mm < 0.2 * r.bop->diameter;
}

// What identifies a target and a method's condition across the two sets.
using PairKey = std::tuple<std::string, std::string, std::string, int, int, int>;  // method, condition, -, scene, im, obj

std::string condition_of(const TrialRecord& r) {
  std::string c = r.params.empty() ? "" : r.params.dump();
  if (r.added_noise_mm != 0) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%snoise %g mm", c.empty() ? "" : ", ", r.added_noise_mm);
    c += buf;
  }
  return c;
}

}  // namespace

std::vector<TwinGapRow> twin_gap(const nlohmann::json& experiment, const std::vector<TrialRecord>& records) {
  std::vector<TwinGapRow> rows;
  if (!experiment.contains("scenes")) return rows;
  for (const auto& sc : experiment["scenes"]) {
    if (!sc.contains("twin_of")) continue;
    const std::string twin = sc.value("name", ""), real = sc["twin_of"].get<std::string>();
    std::map<PairKey, const TrialRecord*> real_trials;
    for (const auto& r : records)
      if (r.scene == real)
        real_trials[{r.descriptor + "+" + r.refinement, condition_of(r), "", r.scene_id, r.im_id, r.obj_id.value_or(0)}] = &r;
    std::map<std::pair<std::string, std::string>, TwinGapRow> by_method;
    for (const auto& t : records) {
      if (t.scene != twin) continue;
      const std::string method = t.descriptor + "+" + t.refinement, cond = condition_of(t);
      const auto it = real_trials.find({method, cond, "", t.scene_id, t.im_id, t.obj_id.value_or(0)});
      if (it == real_trials.end()) continue;
      TwinGapRow& row = by_method[{method, cond}];
      row.real_scene = real, row.twin_scene = twin, row.method = method, row.condition = cond;
      const bool a = found(*it->second), b = found(t);
      ++row.pairs;
      row.real_k += a, row.twin_k += b, row.both += a && b, row.real_only += a && !b, row.twin_only += !a && b;
    }
    for (auto& [k, row] : by_method) {
      row.mcnemar_p = mcnemar_exact_p(row.real_only, row.twin_only);
      rows.push_back(row);
    }
  }
  return rows;
}

std::string twin_gap_markdown(const std::vector<TwinGapRow>& rows) {
  if (rows.empty()) return "";
  std::string md =
      "## Real and twin\n\n"
      "Targets found (MSSD < 0.2 d) on the real frames and on their twins, paired target by target; "
      "McNemar's exact p of the discordant pairs.\n\n"
      "| real | twin | method | condition | real k/n [95%] | twin k/n [95%] | gap (points) | both | real only | twin "
      "only | McNemar p |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  char buf[512];
  for (const auto& r : rows) {
    const Proportion a = r.real(), b = r.twin();
    std::snprintf(buf, sizeof buf,
                  "| %s | %s | %s | %s | %d/%d [%.2f, %.2f] | %d/%d [%.2f, %.2f] | %+.0f | %d | %d | %d | %.3g |\n",
                  r.real_scene.c_str(), r.twin_scene.c_str(), r.method.c_str(), r.condition.c_str(), r.real_k,
                  r.pairs, a.lo, a.hi, r.twin_k, r.pairs, b.lo, b.hi, 100.0 * (b.value() - a.value()), r.both,
                  r.real_only, r.twin_only, r.mcnemar_p);
    md += buf;
  }
  return md + "\n";
}

std::string twin_gap_csv(const std::vector<TwinGapRow>& rows) {
  std::string csv = "real,twin,method,condition,pairs,real_k,twin_k,both,real_only,twin_only,mcnemar_p\n";
  char buf[512];
  for (const auto& r : rows) {
    std::string cond = r.condition;
    for (char& c : cond)
      if (c == ',' || c == '"') c = ';';
    std::snprintf(buf, sizeof buf, "%s,%s,%s,%s,%d,%d,%d,%d,%d,%d,%.6g\n", r.real_scene.c_str(), r.twin_scene.c_str(),
                  r.method.c_str(), cond.c_str(), r.pairs, r.real_k, r.twin_k, r.both, r.real_only, r.twin_only,
                  r.mcnemar_p);
    csv += buf;
  }
  return csv;
}

}  // namespace pb
