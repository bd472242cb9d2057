// The reporter: records of a results folder -> tables in the thesis's layout
// (rows scenario x measure, columns methods, the thesis's value beside each
// cell where one exists), as Markdown, CSV and LaTeX, plus plot data for
// scripts/plot.py (matplotlib). PCL-free.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

#include "eval/record.h"
#include "report/lengths.h"
#include "report/twin_gap.h"

namespace pb {

struct ReportCell {
  double value = 0;       // NaN when undefined (e.g. accuracy with no correct trial)
  double reference = 0;   // the thesis's value, NaN when none
  int trials = 0;
};

struct ReportRow {
  std::string scenario;   // scene set name (e.g. table_astra)
  std::string measure;    // robustness | translation_mm | rotation_1mpq | time | ...
  std::vector<ReportCell> cells;  // parallel to ReportTable::columns
  bool detail = false;            // in the CSV only (e.g. the BOP AR components)
};

struct ReportTable {
  std::string title;
  std::string reference_id;          // thesis table id ("4.1") or ""
  std::string condition;             // grid point / noise level the table is for ("" if one)
  std::vector<std::string> columns;  // methods
  std::vector<ReportRow> rows;
};

struct ReportSeries {                // one curve: a method on a scene set
  std::string label, method, scene;
  std::vector<double> x, robustness, time;
  std::vector<int> correct, trials;  // per point: robustness = correct / trials
};
struct ReportPlot {
  std::string name, x_label, title;  // file stem, axis label in words, the figure's name
  std::vector<ReportSeries> series;
};

struct Report {
  std::string experiment;
  std::vector<ReportTable> tables;
  std::vector<ReportPlot> plots;
  size_t records = 0;
  std::map<std::string, size_t> status_counts;
  std::vector<ResolvedLengths> lengths;  // the lengths the trials resolved, per scene set and object
  std::vector<TwinGapRow> twin_gap;      // real scene sets against their twins (scenes with twin_of)
};

struct ReportOptions {
  std::string reference_file;        // configs/thesis/reference.yaml ("" = none)
  std::string reference_table;       // thesis table id to compare with ("" = from experiment.json)
  std::string plot_x;                // grid path or "added_noise_mm" to plot against ("" = auto)
};

// Builds the report from experiment.json + records (ResultStore format).
Report build_report(const nlohmann::json& experiment, const std::vector<TrialRecord>& records,
                    const ReportOptions& opt);

std::string to_markdown(const Report& r);
// A cell's value as the tables show it (robustness in %, errors in mm...;
// "-" when undefined), and a measure's name in words.
std::string format_measure(double v, const std::string& measure);
std::string measure_label(const std::string& measure);
std::string to_csv(const Report& r);
std::string to_latex(const Report& r);
// What scripts/plot.py draws (report/plots.cpp): per plot its name, title,
// x label and series (label, method, scene, x, robustness, time, correct,
// trials; null for undefined values).
nlohmann::json plots_json(const Report& r);
// The plotted variable in words ("added noise sigma (mm)", "hypotheses
// refined (global.top_k)", else "setting PATH").
std::string plot_axis_label(const std::string& plot_x);
// The plot's title: "Figure 4.6: ..." for a thesis figure's experiment
// (named fig_4_6, fig_4_11_local...), else the experiment's name, with what
// is plotted against what.
std::string plot_title(const std::string& experiment, const std::string& plot_x);

}  // namespace pb
