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

namespace pb {

namespace {

const double kNaN = std::nan("");

std::string column_of(const nlohmann::json& rec, const std::string& mode) {
  const std::string d = rec.value("descriptor", ""), r = rec.value("refinement", "");
  if (mode == "refinement") return r;
  if (mode == "descriptor") return d;
  return d + "+" + r;
}

// The condition a record belongs to: its grid point and noise level, minus
// the plotted variable.
std::string condition_of(const nlohmann::json& rec, const std::string& plot_x) {
  nlohmann::json c = rec.value("params", nlohmann::json::object());
  if (plot_x != "added_noise_mm") c["added_noise_mm"] = rec.value("added_noise_mm", 0.0);
  if (!plot_x.empty() && c.contains(plot_x)) c.erase(plot_x);
  return c.dump();
}

double x_of(const nlohmann::json& rec, const std::string& plot_x) {
  if (plot_x == "added_noise_mm") return rec.value("added_noise_mm", 0.0);
  const auto p = rec.value("params", nlohmann::json::object());
  if (p.contains(plot_x) && p[plot_x].is_number()) return p[plot_x].get<double>();
  return kNaN;
}

ThesisTrial to_trial(const nlohmann::json& rec) {
  ThesisTrial t;
  t.has_pose = rec.value("status", "") == "ok" && rec.contains("errors");
  if (t.has_pose) {
    const auto& e = rec["errors"];
    t.errors.translation_mm = e.value("translation_mm", kNaN);
    t.errors.rotation = e.value("rotation_1mpq", kNaN);
    t.errors.rotation_deg = e.value("rotation_deg", kNaN);
  }
  if (rec.contains("times")) t.time_s = rec["times"].value("total", -1.0);
  return t;
}

// BOP average recalls of a cell: each record is one image with one target
// (the object of interest) and at most one estimate.
BopScores bop_of(const std::vector<const nlohmann::json*>& recs) {
  std::vector<BopImageErrors> images;
  for (const auto* r : recs) {
    BopImageErrors im;
    im.scene_id = r->value("scene_id", 0);
    im.im_id = static_cast<int>(images.size());
    BopTarget tgt;
    tgt.obj_id = r->value("obj_id", 1);
    im.gts.push_back(tgt);
    if (r->value("status", "") == "ok" && r->contains("bop")) {
      const auto& b = (*r)["bop"];
      im.image_width = b.value("image_width", 640);
      BopEstimateErrors est;
      est.obj_id = tgt.obj_id;
      est.score = r->value("score", 1.0);
      est.diameter = b.value("diameter", 0.0);
      BopPairErrors pair;
      pair.gt = 0;
      pair.mssd_mm = b.value("mssd_mm", HUGE_VAL);
      pair.mspd_px = b.value("mspd_px", HUGE_VAL);
      pair.vsd = b.value("vsd", std::vector<double>{});
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

std::string fmt(double v, const std::string& measure) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  if (measure == "robustness")
    std::snprintf(buf, sizeof buf, "%.0f%%", 100 * v);
  else if (measure == "rotation_1mpq" || measure == "rotation_1mpq_std")
    std::snprintf(buf, sizeof buf, "%.4f", v);
  else if (measure == "time" || measure.rfind("bop_ar", 0) == 0)
    std::snprintf(buf, sizeof buf, "%.2f", v);
  else
    std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

}  // namespace

Report build_report(const nlohmann::json& exp, const std::vector<nlohmann::json>& records,
                    const ReportOptions& opt) {
  Report rep;
  rep.experiment = exp.value("name", "");
  rep.records = records.size();
  for (const auto& r : records) ++rep.status_counts[r.value("status", "?")];

  const auto rcfg = exp.value("report", nlohmann::json::object());
  const bool reg_only = exp.value("registration_only", false);
  std::string mode = rcfg.value("columns", "");
  if (mode.empty()) {
    const auto refs = exp.value("refinements", nlohmann::json::array());
    const auto descs = exp.value("descriptors", nlohmann::json::array());
    mode = reg_only ? "refinement" : (refs.size() > 1 && descs.size() > 1) ? "method"
                                     : refs.size() > 1                      ? "refinement"
                                                                            : "descriptor";
  }
  std::string plot_x = opt.plot_x.empty() ? rcfg.value("plot_x", "") : opt.plot_x;
  if (plot_x.empty()) {
    if (exp.value("added_noise_mm", nlohmann::json::array()).size() > 1) plot_x = "added_noise_mm";
    for (const auto& g : exp.value("grid", nlohmann::json::array()))
      if (plot_x.empty() && g.size() == 2 && g[1].size() > 1) plot_x = g[0].get<std::string>();
  }
  const std::string ref_id = opt.reference_table.empty() ? rcfg.value("reference_table", "") : opt.reference_table;
  const Reference ref = load_reference(opt.reference_file, ref_id);

  // Column order: as configured.
  std::vector<std::string> columns;
  auto add_col = [&](const std::string& c) {
    if (std::find(columns.begin(), columns.end(), c) == columns.end()) columns.push_back(c);
  };
  for (const auto& r : records) add_col(column_of(r, mode));
  {
    std::vector<std::string> ordered;
    const auto descs = exp.value("descriptors", std::vector<std::string>{});
    const auto refs = exp.value("refinements", std::vector<std::string>{});
    for (const auto& d : descs)
      for (const auto& f : refs) {
        const std::string c = mode == "descriptor" ? d : mode == "refinement" ? f : d + "+" + f;
        if (std::find(columns.begin(), columns.end(), c) != columns.end() &&
            std::find(ordered.begin(), ordered.end(), c) == ordered.end())
          ordered.push_back(c);
      }
    for (const auto& c : columns)
      if (std::find(ordered.begin(), ordered.end(), c) == ordered.end()) ordered.push_back(c);
    columns = ordered;
  }
  std::vector<std::string> scenes;
  for (const auto& s : exp.value("scenes", nlohmann::json::array())) scenes.push_back(s.value("name", ""));
  std::map<std::string, std::string> scenario_of;
  for (const auto& s : exp.value("scenes", nlohmann::json::array()))
    scenario_of[s.value("name", "")] = s.value("scenario", "table");

  // Tables: one per condition (grid point and noise level, except the plotted variable).
  std::map<std::string, std::vector<const nlohmann::json*>> by_cond;
  std::vector<std::string> cond_order;
  for (const auto& r : records) {
    const std::string c = condition_of(r, "");
    if (!by_cond.count(c)) cond_order.push_back(c);
    by_cond[c].push_back(&r);
  }
  std::sort(cond_order.begin(), cond_order.end());
  for (const auto& cond : cond_order) {
    ReportTable t;
    t.reference_id = ref_id;
    t.title = ref.title.empty() ? rep.experiment : "Table " + ref_id + ": " + ref.title;
    if (cond != "{}" && cond != "{\"added_noise_mm\":0.0}") t.condition = cond;
    t.columns = columns;
    const std::vector<std::string> measures =
        std::vector<std::string>{"robustness", "translation_mm", "rotation_1mpq", "time", "bop_ar",
                                 "bop_ar_vsd", "bop_ar_mssd", "bop_ar_mspd"};
    for (const auto& scene : scenes) {
      std::map<std::string, ThesisAggregate> agg;
      std::map<std::string, BopScores> bop;
      std::map<std::string, int> count;
      for (const auto& col : columns) {
        std::vector<ThesisTrial> trials;
        std::vector<const nlohmann::json*> recs;
        for (const auto* r : by_cond[cond])
          if (r->value("scene", "") == scene && column_of(*r, mode) == col) {
            trials.push_back(to_trial(*r));
            recs.push_back(r);
          }
        if (!recs.empty()) bop[col] = bop_of(recs);
        count[col] = static_cast<int>(trials.size());
        // Correctness was decided by the runner with the experiment's
        // thresholds; recompute here from the stored errors with the same ones.
        agg[col] = thesis_aggregate(trials, thresholds_for(exp, scenario_of[scene]));
      }
      bool any = false;
      for (const auto& col : columns) any |= count[col] > 0;
      if (!any) continue;
      for (const auto& m : measures) {
        ReportRow row;
        row.scenario = scene;
        row.measure = m;
        row.detail = m.rfind("bop_ar_", 0) == 0;
        for (const auto& col : columns) {
          const ThesisAggregate& a = agg[col];
          ReportCell cell;
          cell.trials = count[col];
          const bool has_bop = bop.count(col) > 0;
          const BopScores b = has_bop ? bop[col] : BopScores{};
          cell.value = m == "robustness"       ? (a.trials ? a.robustness : kNaN)
                       : m == "translation_mm" ? a.translation_mean_mm
                       : m == "rotation_1mpq"  ? a.rotation_mean
                       : m == "time"           ? a.time_mean_s
                       : !has_bop              ? kNaN
                       : m == "bop_ar"         ? b.ar
                       : m == "bop_ar_vsd"     ? b.ar_vsd
                       : m == "bop_ar_mssd"    ? b.ar_mssd
                                               : b.ar_mspd;
          const std::string method = mode == "method" ? col.substr(0, col.find('+')) : col;
          cell.reference = ref_value(ref, scene, m, method);
          row.cells.push_back(cell);
        }
        t.rows.push_back(row);
      }
    }
    rep.tables.push_back(t);
  }

  // Plots: robustness and time against the plotted variable.
  if (!plot_x.empty()) {
    ReportPlot p;
    p.name = plot_x == "added_noise_mm" ? "robustness_vs_noise" : "robustness_vs_" + plot_x;
    std::replace(p.name.begin(), p.name.end(), '.', '_');
    p.x_label = plot_x == "added_noise_mm" ? "added noise sigma (mm)" : plot_x;
    for (const auto& scene : scenes)
      for (const auto& col : columns) {
        std::map<double, std::vector<ThesisTrial>> pts;
        for (const auto& r : records)
          if (r.value("scene", "") == scene && column_of(r, mode) == col) {
            const double x = x_of(r, plot_x);
            if (std::isfinite(x)) pts[x].push_back(to_trial(r));
          }
        if (pts.empty()) continue;
        ReportSeries s;
        s.label = col + " (" + scene + ")";
        for (const auto& [x, trials] : pts) {
          const ThesisAggregate a = thesis_aggregate(trials, thresholds_for(exp, scenario_of[scene]));
          s.x.push_back(x);
          s.robustness.push_back(a.robustness);
          s.time.push_back(a.time_mean_s);
        }
        p.series.push_back(s);
      }
    rep.plots.push_back(p);
  }
  return rep;
}

static const char* measure_label(const std::string& m) {
  if (m == "robustness") return "robustness";
  if (m == "translation_mm") return "translation error (mm)";
  if (m == "rotation_1mpq") return "rotation error (1-|p.q|)";
  if (m == "time") return "time (s)";
  if (m == "bop_ar") return "BOP AR (VSD, MSSD, MSPD)";
  return m.c_str();
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
        o << " " << fmt(c.value, row.measure);
        if (std::isfinite(c.reference)) o << " (" << fmt(c.reference, row.measure) << ")";
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
        o << " & " << tex_escape(fmt(c.value, row.measure));
        if (std::isfinite(c.reference)) o << " (" << tex_escape(fmt(c.reference, row.measure)) << ")";
      }
      o << " \\\\\n";
    }
    o << "\\hline\n\\end{tabular}\n\n";
  }
  return o.str();
}

nlohmann::json plots_json(const Report& r) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& p : r.plots) {
    nlohmann::json pj = {{"name", p.name}, {"x_label", p.x_label}, {"title", r.experiment}};
    for (const auto& s : p.series) {
      auto clean = [](const std::vector<double>& v) {
        nlohmann::json a = nlohmann::json::array();
        for (double x : v) a.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr));
        return a;
      };
      pj["series"].push_back({{"label", s.label}, {"x", clean(s.x)}, {"robustness", clean(s.robustness)},
                              {"time", clean(s.time)}});
    }
    j.push_back(pj);
  }
  return j;
}

}  // namespace pb
