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
  std::string label;
  std::vector<double> x, robustness, time;
};
struct ReportPlot {
  std::string name, x_label;         // file stem, axis label
  std::vector<ReportSeries> series;
};

struct Report {
  std::string experiment;
  std::vector<ReportTable> tables;
  std::vector<ReportPlot> plots;
  size_t records = 0;
  std::map<std::string, size_t> status_counts;
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
nlohmann::json plots_json(const Report& r);

}  // namespace pb
