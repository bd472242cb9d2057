#include "report/bench.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace pb {

namespace {

struct Samples {
  BenchRow row;
  int correct_k = 0, correct_n = 0;  // records with a thesis judgement, and of those correct
  std::vector<double> pre, hyp, ref, ver, tot, nh;
};

std::string ms(double s) {
  if (!std::isfinite(s)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, s < 0.01 ? "%.2f" : (s < 1 ? "%.1f" : "%.0f"), s * 1000);
  return b;
}

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

BenchTable bench_table(const std::vector<TrialRecord>& records, const std::map<std::string, double>& budgets_s) {
  std::vector<Samples> groups;
  std::map<std::string, size_t> index;
  for (const TrialRecord& r : records) {
    const std::string key = r.scene + "\n" + r.descriptor + "\n" + r.refinement;
    auto it = index.find(key);
    if (it == index.end()) {
      it = index.emplace(key, groups.size()).first;
      Samples s;
      s.row.scene = r.scene;
      s.row.scenario = r.scenario;
      s.row.descriptor = r.descriptor;
      s.row.refinement = r.refinement;
      const auto b = budgets_s.find(r.scenario);
      s.row.budget_s = b == budgets_s.end() ? 0 : b->second;
      groups.push_back(s);
    }
    Samples& g = groups[it->second];
    ++g.row.trials;
    if (r.status == "ok") ++g.row.ok;
    if (r.correct) {
      ++g.correct_n;
      if (*r.correct) ++g.correct_k;
    }
    if (r.times) {
      const StageTimes& t = r.times->stages;
      g.pre.push_back(t.preprocess);
      g.hyp.push_back(t.describe + t.match + t.group + t.initial_pose);
      g.ref.push_back(t.refine);
      g.ver.push_back(t.verify);
      g.tot.push_back(r.times->total);
    }
    if (r.hypotheses) g.nh.push_back(*r.hypotheses);
  }
  BenchTable t;
  for (Samples& g : groups) {
    BenchRow& r = g.row;
    r.correct = wilson(g.correct_k, g.correct_n);
    r.preprocess_s = median(g.pre);
    r.hypothesize_s = median(g.hyp);
    r.refine_s = median(g.ref);
    r.verify_s = median(g.ver);
    r.total_s = median(g.tot);
    r.total_p90_s = quantile(g.tot, 0.9);
    r.hypotheses = median(g.nh);
    t.rows.push_back(r);
  }
  return t;
}

nlohmann::json bench_json(const BenchTable& t) {
  nlohmann::json rows = nlohmann::json::array();
  for (const BenchRow& r : t.rows)
    rows.push_back({{"scene", r.scene},
                    {"scenario", r.scenario},
                    {"descriptor", r.descriptor},
                    {"refinement", r.refinement},
                    {"trials", r.trials},
                    {"ok", r.ok},
                    {"correct", {{"k", r.correct.k}, {"n", r.correct.n}, {"lo95", r.correct.lo}, {"hi95", r.correct.hi}}},
                    {"median_s",
                     {{"preprocess", num(r.preprocess_s)},
                      {"hypothesize", num(r.hypothesize_s)},
                      {"refine", num(r.refine_s)},
                      {"verify", num(r.verify_s)},
                      {"total", num(r.total_s)}}},
                    {"p90_total_s", num(r.total_p90_s)},
                    {"median_hypotheses", num(r.hypotheses)},
                    {"budget_s", r.budget_s},
                    {"within_budget", r.within_budget()}});
  return {{"host", t.host}, {"settings", t.settings}, {"rows", rows}};
}

std::string bench_markdown(const BenchTable& t) {
  std::ostringstream o;
  o << "Milliseconds per image (median over the images; p90 of the total), the online computation only "
       "(training excluded); correct = the thesis's judgement, k/n with a 95% Wilson interval.\n\n";
  if (!t.host.empty()) o << "Host: " << t.host.dump() << "\n\n";
  o << "| scene | method | preprocess | hypothesize | refine | verify | total | p90 | budget | hyps | correct |\n"
       "|---|---|---:|---:|---:|---:|---:|---:|---|---:|---|\n";
  for (const BenchRow& r : t.rows) {
    char c[96];
    std::snprintf(c, sizeof c, "%d/%d [%.0f-%.0f%%]", r.correct.k, r.correct.n, 100 * r.correct.lo,
                  100 * r.correct.hi);
    std::string budget = "-";
    if (r.budget_s > 0) budget = ms(r.budget_s) + (r.within_budget() ? " met" : " missed");
    o << "| " << r.scene << " | " << r.descriptor << "+" << r.refinement << " | " << ms(r.preprocess_s) << " | "
      << ms(r.hypothesize_s) << " | " << ms(r.refine_s) << " | " << ms(r.verify_s) << " | " << ms(r.total_s)
      << " | " << ms(r.total_p90_s) << " | " << budget << " | "
      << (std::isfinite(r.hypotheses) ? std::to_string(static_cast<int>(std::lround(r.hypotheses))) : "-")
      << " | " << c << " |\n";
  }
  if (!t.settings.empty()) {
    o << "\nSettings over the defaults (as the config gives them; every resolved value is in the records' "
         "settings_resolved):\n\n";
    for (auto it = t.settings.begin(); it != t.settings.end(); ++it)
      o << "- " << (it.key() == "all" ? std::string("every scene set") : it.key()) << ": `" << it.value().dump()
        << "`\n";
  }
  return o.str();
}

}  // namespace pb
