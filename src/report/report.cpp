#include "report/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/yaml.h"
#include "eval/bop_metrics.h"
#include "eval/errors.h"
#include "eval/record.h"

namespace pb {

namespace {

const double kNaN = std::nan("");

std::string column_of(const TrialRecord& rec, const std::string& mode) {
  const std::string &d = rec.descriptor, &r = rec.refinement;
  if (mode == "refinement") return r;
  if (mode == "descriptor") return d;
  return d + "+" + r;
}

// The condition a record belongs to: its grid point and noise level, minus
// the plotted variable.
std::string condition_of(const TrialRecord& rec, const std::string& plot_x) {
  nlohmann::json c = rec.params;
  if (plot_x != "added_noise_mm") c["added_noise_mm"] = rec.added_noise_mm;
  if (!plot_x.empty() && c.contains(plot_x)) c.erase(plot_x);
  return c.dump();
}

double x_of(const TrialRecord& rec, const std::string& plot_x) {
  if (plot_x == "added_noise_mm") return rec.added_noise_mm;
  const auto& p = rec.params;
  if (p.contains(plot_x) && p[plot_x].is_number()) return p[plot_x].get<double>();
  return kNaN;
}

ThesisTrial to_trial(const TrialRecord& rec) {
  ThesisTrial t;
  t.has_pose = rec.status == "ok" && rec.errors.has_value();
  if (t.has_pose) {
    t.errors.translation_mm = rec.errors->translation_mm;
    t.errors.rotation = rec.errors->rotation_1mpq;
    t.errors.rotation_deg = rec.errors->rotation_deg;
  }
  if (rec.times) t.time_s = rec.times->total;
  return t;
}

// BOP average recalls of a cell: each record is one image with one target
// (the object of interest) and at most one estimate.
BopScores bop_of(const std::vector<const TrialRecord*>& recs) {
  std::vector<BopImageErrors> images;
  for (const auto* r : recs) {
    BopImageErrors im;
    im.scene_id = r->scene_id;
    im.im_id = static_cast<int>(images.size());
    BopTarget tgt;
    tgt.obj_id = r->obj_id.value_or(1);
    im.gts.push_back(tgt);
    if (r->status == "ok" && r->bop) {
      const BopErrorsRecord& b = *r->bop;
      im.image_width = b.image_width;
      BopEstimateErrors est;
      est.obj_id = tgt.obj_id;
      est.score = r->score.value_or(1.0);
      est.diameter = b.diameter;
      BopPairErrors pair;
      pair.gt = 0;
      pair.mssd_mm = b.mssd_mm;
      pair.mspd_px = b.mspd_px;
      pair.vsd = b.vsd;
      est.pairs.push_back(pair);
      im.estimates.push_back(est);
    }
    images.push_back(im);
  }
  return bop_scores(images);
}

ThesisThresholds thresholds_for(const nlohmann::json& exp, const std::string& scenario) {
  ThesisThresholds thr;
  const auto t = exp.value("thresholds", nlohmann::json::array());
  const double table = t.size() == 3 ? t[0].get<double>() : 50.0;
  const double wh = t.size() == 3 ? t[1].get<double>() : 100.0;
  thr.rotation = t.size() == 3 ? t[2].get<double>() : 0.05;
  thr.translation_mm = scenario == "warehouse" ? wh : table;
  return thr;
}

struct Reference {
  std::map<std::string, std::map<std::string, std::map<std::string, double>>> v;  // row -> measure -> method
  std::string title;
};

Reference load_reference(const std::string& file, const std::string& id) {
  Reference ref;
  if (file.empty() || id.empty()) return ref;
  const YamlNode root = YamlNode::load_file(file);
  const YamlNode t = root["tables"][id];
  if (!t.defined()) throw InputError(file, "tables." + id, "no such thesis table");
  ref.title = t.get_or<std::string>("title", "");
  const auto methods = t.get<std::vector<std::string>>("methods");
  const YamlNode rows = t["rows"];
  for (const auto& row : rows.keys())
    for (const auto& measure : rows[row].keys()) {
      const auto vals = rows[row].get<std::vector<double>>(measure);
      if (vals.size() != methods.size()) rows[row][measure].fail("expected one value per method");
      for (size_t i = 0; i < vals.size(); ++i) ref.v[row][measure][methods[i]] = vals[i];
    }
  return ref;
}

double ref_value(const Reference& ref, const std::string& row, const std::string& measure,
                 const std::string& method) {
  auto a = ref.v.find(row);
  if (a == ref.v.end()) return kNaN;
  auto b = a->second.find(measure);
  if (b == a->second.end()) return kNaN;
  auto c = b->second.find(method);
  return c == b->second.end() ? kNaN : c->second;
}

}  // namespace

std::string format_measure(double v, const std::string& measure) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  if (measure.rfind("robustness", 0) == 0)
    std::snprintf(buf, sizeof buf, "%.0f%%", 100 * v);
  else if (measure == "rotation_1mpq" || measure == "rotation_1mpq_std")
    std::snprintf(buf, sizeof buf, "%.4f", v);
  else if (measure == "time" || measure.rfind("bop_ar", 0) == 0)
    std::snprintf(buf, sizeof buf, "%.2f", v);
  else
    std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

namespace {

// How the records of an experiment are laid out in tables.
struct Layout {
  std::string mode;      // columns: descriptor | refinement | method (descriptor+refinement)
  std::string plot_x;    // the swept variable plotted ("" = none)
  std::string ref_id;    // thesis table compared with
  std::vector<std::string> columns, scenes;
  std::map<std::string, std::string> scenario_of;
  std::vector<std::string> judgements;  // extra judgements the records carry (experiment `judgements:`)
};

Layout layout_of(const nlohmann::json& exp, const std::vector<TrialRecord>& records, const ReportOptions& opt) {
  Layout l;
  const auto rcfg = exp.value("report", nlohmann::json::object());
  const bool reg_only = exp.value("registration_only", false);
  l.mode = rcfg.value("columns", "");
  const auto descs = exp.value("descriptors", std::vector<std::string>{});
  const auto refs = exp.value("refinements", std::vector<std::string>{});
  if (l.mode.empty())
    l.mode = reg_only ? "refinement" : (refs.size() > 1 && descs.size() > 1) ? "method"
                                     : refs.size() > 1                      ? "refinement"
                                                                            : "descriptor";
  l.plot_x = opt.plot_x.empty() ? rcfg.value("plot_x", "") : opt.plot_x;
  if (l.plot_x.empty()) {
    if (exp.value("added_noise_mm", nlohmann::json::array()).size() > 1) l.plot_x = "added_noise_mm";
    for (const auto& g : exp.value("grid", nlohmann::json::array()))
      if (l.plot_x.empty() && g.size() == 2 && g[1].size() > 1) l.plot_x = g[0].get<std::string>();
  }
  l.ref_id = opt.reference_table.empty() ? rcfg.value("reference_table", "") : opt.reference_table;
  // Column order: as configured, then any other found in the records.
  std::vector<std::string> found;
  for (const auto& r : records) {
    const std::string c = column_of(r, l.mode);
    if (std::find(found.begin(), found.end(), c) == found.end()) found.push_back(c);
  }
  for (const auto& d : descs)
    for (const auto& f : refs) {
      const std::string c = l.mode == "descriptor" ? d : l.mode == "refinement" ? f : d + "+" + f;
      if (std::find(found.begin(), found.end(), c) != found.end() &&
          std::find(l.columns.begin(), l.columns.end(), c) == l.columns.end())
        l.columns.push_back(c);
    }
  for (const auto& c : found)
    if (std::find(l.columns.begin(), l.columns.end(), c) == l.columns.end()) l.columns.push_back(c);
  for (const auto& s : exp.value("scenes", nlohmann::json::array())) {
    l.scenes.push_back(s.value("name", ""));
    l.scenario_of[s.value("name", "")] = s.value("scenario", "table");
  }
  std::set<std::string> judged;
  for (const auto& r : records)
    for (const auto& [name, j] : r.judgements) judged.insert(name);
  l.judgements.assign(judged.begin(), judged.end());
  return l;
}

// Robustness under an extra judgement (e.g. the carton's faces on faces):
// the share of trials whose record judges its pose correct that way; a
// trial without a judged pose counts as not correct.
double judged_robustness(const std::vector<const TrialRecord*>& recs, const std::string& name) {
  if (recs.empty()) return kNaN;
  size_t correct = 0;
  for (const auto* r : recs) {
    const auto it = r->judgements.find(name);
    if (it != r->judgements.end() && it->second.correct) ++correct;
  }
  return static_cast<double>(correct) / static_cast<double>(recs.size());
}

// The measure of the row of an extra judgement.
std::string judgement_measure(const std::string& name) { return "robustness_" + name; }

const std::vector<std::string>& table_measures() {
  static const std::vector<std::string> m{"robustness", "translation_mm", "rotation_1mpq", "time", "bop_ar",
                                          "bop_ar_vsd", "bop_ar_mssd", "bop_ar_mspd"};
  return m;
}

// The rows of one scene set in one condition's table.
void add_scene_rows(const std::string& scene, const std::vector<const TrialRecord*>& recs_of_cond,
                    const Layout& l, const nlohmann::json& exp, const Reference& ref, ReportTable& t) {
  std::map<std::string, ThesisAggregate> agg;
  std::map<std::string, BopScores> bop;
  std::map<std::string, int> count;
  std::map<std::string, std::map<std::string, double>> judged;  // measure -> column -> robustness
  for (const auto& col : l.columns) {
    std::vector<ThesisTrial> trials;
    std::vector<const TrialRecord*> recs;
    for (const auto* r : recs_of_cond)
      if (r->scene == scene && column_of(*r, l.mode) == col) {
        trials.push_back(to_trial(*r));
        recs.push_back(r);
      }
    if (!recs.empty()) bop[col] = bop_of(recs);
    for (const auto& name : l.judgements) judged[judgement_measure(name)][col] = judged_robustness(recs, name);
    count[col] = static_cast<int>(trials.size());
    // Correctness was decided by the runner with the experiment's
    // thresholds; recompute here from the stored errors with the same ones.
    agg[col] = thesis_aggregate(trials, thresholds_for(exp, l.scenario_of.at(scene)));
  }
  bool any = false;
  for (const auto& col : l.columns) any |= count[col] > 0;
  if (!any) return;
  std::vector<std::string> measures = table_measures();  // the judgements' robustness after the main one
  for (size_t i = 0; i < l.judgements.size(); ++i)
    measures.insert(measures.begin() + static_cast<long>(1 + i), judgement_measure(l.judgements[i]));
  for (const auto& m : measures) {
    ReportRow row;
    row.scenario = scene;
    row.measure = m;
    row.detail = m.rfind("bop_ar_", 0) == 0;
    for (const auto& col : l.columns) {
      const ThesisAggregate& a = agg[col];
      ReportCell cell;
      cell.trials = count[col];
      const bool has_bop = bop.count(col) > 0;
      const BopScores b = has_bop ? bop[col] : BopScores{};
      cell.value = judged.count(m)         ? judged[m][col]
                   : m == "robustness"     ? (a.trials ? a.robustness : kNaN)
                   : m == "translation_mm" ? a.translation_mean_mm
                   : m == "rotation_1mpq"  ? a.rotation_mean
                   : m == "time"           ? a.time_mean_s
                   : !has_bop              ? kNaN
                   : m == "bop_ar"         ? b.ar
                   : m == "bop_ar_vsd"     ? b.ar_vsd
                   : m == "bop_ar_mssd"    ? b.ar_mssd
                                           : b.ar_mspd;
      const std::string method = l.mode == "method" ? col.substr(0, col.find('+')) : col;
      cell.reference = ref_value(ref, scene, m, method);
      row.cells.push_back(cell);
    }
    t.rows.push_back(row);
  }
}

// Robustness and time against the plotted variable, one series per method
// and scene set.
ReportPlot plot_of(const std::vector<TrialRecord>& records, const Layout& l, const nlohmann::json& exp) {
  ReportPlot p;
  p.name = l.plot_x == "added_noise_mm" ? "robustness_vs_noise" : "robustness_vs_" + l.plot_x;
  std::replace(p.name.begin(), p.name.end(), '.', '_');
  p.x_label = plot_axis_label(l.plot_x);
  p.title = plot_title(exp.value("name", ""), l.plot_x);
  for (const auto& scene : l.scenes)
    for (const auto& col : l.columns) {
      std::map<double, std::vector<ThesisTrial>> pts;
      for (const auto& r : records)
        if (r.scene == scene && column_of(r, l.mode) == col) {
          const double x = x_of(r, l.plot_x);
          if (std::isfinite(x)) pts[x].push_back(to_trial(r));
        }
      if (pts.empty()) continue;
      ReportSeries s;
      s.label = col + " (" + scene + ")";
      s.method = col;
      s.scene = scene;
      for (const auto& [x, trials] : pts) {
        const ThesisAggregate a = thesis_aggregate(trials, thresholds_for(exp, l.scenario_of.at(scene)));
        s.x.push_back(x);
        s.robustness.push_back(a.robustness);
        s.time.push_back(a.time_mean_s);
        s.correct.push_back(a.correct);
        s.trials.push_back(a.trials);
      }
      p.series.push_back(s);
    }
  return p;
}

}  // namespace

Report build_report(const nlohmann::json& exp, const std::vector<TrialRecord>& records, const ReportOptions& opt) {
  Report rep;
  rep.experiment = exp.value("name", "");
  rep.records = records.size();
  for (const auto& r : records) ++rep.status_counts[r.status];
  rep.lengths = resolved_lengths(records);
  rep.twin_gap = twin_gap(exp, records);
  const Layout l = layout_of(exp, records, opt);
  const Reference ref = load_reference(opt.reference_file, l.ref_id);

  // Tables: one per condition (grid point and noise level).
  std::map<std::string, std::vector<const TrialRecord*>> by_cond;
  for (const auto& r : records) by_cond[condition_of(r, "")].push_back(&r);
  for (const auto& [cond, recs] : by_cond) {
    ReportTable t;
    t.reference_id = l.ref_id;
    t.title = ref.title.empty() ? rep.experiment : "Table " + l.ref_id + ": " + ref.title;
    if (cond != "{}" && cond != "{\"added_noise_mm\":0.0}") t.condition = cond;
    t.columns = l.columns;
    for (const auto& scene : l.scenes) add_scene_rows(scene, recs, l, exp, ref, t);
    rep.tables.push_back(t);
  }
  if (!l.plot_x.empty()) rep.plots.push_back(plot_of(records, l, exp));
  return rep;
}

std::string measure_label(const std::string& m) {
  if (m == "robustness") return "robustness";
  if (m.rfind("robustness_", 0) == 0) return "robustness, judged by " + m.substr(11);
  if (m == "translation_mm") return "translation error (mm)";
  if (m == "rotation_1mpq") return "rotation error (1-|p.q|)";
  if (m == "time") return "time (s)";
  if (m == "bop_ar") return "BOP AR (VSD, MSSD, MSPD)";
  return m;
}

std::string to_markdown(const Report& r) {
  std::ostringstream o;
  for (const auto& t : r.tables) {
    o << "### " << t.title << "\n\n";
    if (!t.condition.empty()) o << "Condition: `" << t.condition << "`\n\n";
    const bool has_ref = std::any_of(t.rows.begin(), t.rows.end(), [](const ReportRow& row) {
      return std::any_of(row.cells.begin(), row.cells.end(), [](const ReportCell& c) { return std::isfinite(c.reference); });
    });
    o << "| scenario | measure |";
    for (const auto& c : t.columns) o << " " << c << " |";
    o << "\n|---|---|";
    for (size_t i = 0; i < t.columns.size(); ++i) o << "---|";
    o << "\n";
    std::string last;
    for (const auto& row : t.rows) {
      if (row.detail) continue;
      o << "| " << (row.scenario == last ? "" : row.scenario) << " | " << measure_label(row.measure) << " |";
      last = row.scenario;
      for (const auto& c : row.cells) {
        o << " " << format_measure(c.value, row.measure);
        if (std::isfinite(c.reference)) o << " (" << format_measure(c.reference, row.measure) << ")";
        o << " |";
      }
      o << "\n";
    }
    int n = 0;
    for (const auto& row : t.rows)
      for (const auto& c : row.cells) n = std::max(n, c.trials);
    o << "\n" << (has_ref ? "In parentheses: the thesis's value. " : "") << "Up to " << n
      << " trials per cell; accuracy over correct trials only.\n\n";
  }
  o << twin_gap_markdown(r.twin_gap);
  o << resolved_lengths_markdown(r.lengths);
  o << "Records: " << r.records;
  for (const auto& [k, v] : r.status_counts) o << ", " << k << " " << v;
  o << "\n";
  return o.str();
}

std::string to_csv(const Report& r) {
  std::ostringstream o;
  o << "table,condition,scenario,measure,method,value,thesis,trials\n";
  for (const auto& t : r.tables)
    for (const auto& row : t.rows)
      for (size_t i = 0; i < row.cells.size(); ++i) {
        std::string cond = t.condition;
        std::replace(cond.begin(), cond.end(), ',', ';');
        std::replace(cond.begin(), cond.end(), '"', '\'');
        o << t.reference_id << "," << cond << "," << row.scenario << "," << row.measure << "," << t.columns[i]
          << ",";
        if (std::isfinite(row.cells[i].value)) o << row.cells[i].value;
        o << ",";
        if (std::isfinite(row.cells[i].reference)) o << row.cells[i].reference;
        o << "," << row.cells[i].trials << "\n";
      }
  return o.str();
}

static std::string tex_escape(std::string s) {
  std::string o;
  for (char c : s) {
    if (c == '_' || c == '%' || c == '&' || c == '#') o += '\\';
    o += c;
  }
  return o;
}

std::string to_latex(const Report& r) {
  std::ostringstream o;
  for (const auto& t : r.tables) {
    o << "% " << t.title << (t.condition.empty() ? "" : " " + t.condition) << "\n";
    o << "\\begin{tabular}{ll" << std::string(t.columns.size(), 'r') << "}\n\\hline\nscenario & measure";
    for (const auto& c : t.columns) o << " & " << tex_escape(c);
    o << " \\\\\n\\hline\n";
    for (const auto& row : t.rows) {
      if (row.detail) continue;
      o << tex_escape(row.scenario) << " & " << tex_escape(measure_label(row.measure));
      for (const auto& c : row.cells) {
        o << " & " << tex_escape(format_measure(c.value, row.measure));
        if (std::isfinite(c.reference)) o << " (" << tex_escape(format_measure(c.reference, row.measure)) << ")";
      }
      o << " \\\\\n";
    }
    o << "\\hline\n\\end{tabular}\n\n";
  }
  return o.str();
}

}  // namespace pb
