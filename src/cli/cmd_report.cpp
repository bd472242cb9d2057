// posebench report results/NAME [--format md,csv,tex] [--plots]
#include <algorithm>
#include <cstdlib>
#include <map>
#include <tuple>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <iostream>
#include <sstream>

#include "cli/command.h"
#include "core/error.h"
#include "core/log.h"
#include "io/png.h"
#include "eval/bop_csv.h"
#include "report/gallery.h"
#include "report/html.h"
#include "report/report.h"
#include "runner/store.h"

namespace fs = std::filesystem;

static std::string find_reference() {
#ifdef POSEBENCH_SOURCE_DIR
  const fs::path p = fs::path(POSEBENCH_SOURCE_DIR) / "configs/thesis/reference.yaml";
  if (fs::exists(p)) return p.string();
#endif
  if (fs::exists("configs/thesis/reference.yaml")) return "configs/thesis/reference.yaml";
  return "";
}

static std::string find_plot_script() {
#ifdef POSEBENCH_SOURCE_DIR
  const fs::path p = fs::path(POSEBENCH_SOURCE_DIR) / "scripts/plot.py";
  if (fs::exists(p)) return p.string();
#endif
  return fs::exists("scripts/plot.py") ? "scripts/plot.py" : "";
}

// experiment.json of a results folder (the canonical config the run wrote).
static nlohmann::json read_experiment_json(const std::string& dir) {
  const fs::path exp_path = fs::path(dir) / "experiment.json";
  if (!fs::exists(exp_path)) throw pb::InputError(exp_path.string(), "", "not a posebench results folder");
  nlohmann::json exp;
  try {
    std::ifstream in(exp_path);
    in >> exp;
  } catch (const nlohmann::json::exception& e) {
    throw pb::InputError(exp_path.string(), "", std::string("malformed: ") + e.what());
  }
  return exp;
}

// REPORT.{md,csv,tex} for the comma-separated `formats`; the Markdown also
// goes to stdout.
static void write_tables(const pb::Report& rep, const std::string& dir, const std::string& formats) {
  std::stringstream fs_(formats);
  std::string f;
  while (std::getline(fs_, f, ',')) {
    if (f == "md") {
      const std::string md = "# " + rep.experiment + "\n\n" + pb::to_markdown(rep);
      pb::atomic_write_text((fs::path(dir) / "report.md").string(), md);
      std::cout << md;
    } else if (f == "csv") {
      pb::atomic_write_text((fs::path(dir) / "report.csv").string(), pb::to_csv(rep));
      if (!rep.twin_gap.empty())
        pb::atomic_write_text((fs::path(dir) / "twin_gap.csv").string(), pb::twin_gap_csv(rep.twin_gap));
    } else if (f == "tex") {
      pb::atomic_write_text((fs::path(dir) / "report.tex").string(), pb::to_latex(rep));
    } else {
      throw pb::InputError("", "--format", "unknown format '" + f + "' (md, csv, tex)");
    }
  }
}

// The BOP results file a record's estimate goes to: METHOD_DATASET-SPLIT.csv,
// one per method, condition (grid point, noise) and scene set. BOP parses
// the name: no '_' in the method, no '_' or '-' in the dataset name.
static std::string bop_csv_name(const pb::TrialRecord& r) {
  std::string method = "posebench-" + r.descriptor + "-" + r.refinement;
  for (auto it = r.params.begin(); it != r.params.end(); ++it) method += "-" + it.key() + "=" + it.value().dump();
  if (r.added_noise_mm > 0) method += "-noise=" + nlohmann::json(r.added_noise_mm).dump();
  for (char& c : method)
    if (c == '_' || c == '/' || c == '"' || c == ' ') c = '.';
  std::string dataset = r.scene;
  dataset.erase(std::remove_if(dataset.begin(), dataset.end(), [](char c) { return c == '_' || c == '-'; }),
                dataset.end());
  return method + "_" + dataset + "-" + r.split + ".csv";
}

// BOP results CSVs in DIR/bop (every estimate), so the BOP toolkit itself
// can score them. A multi-instance record (BOP test targets) gives a row per
// instance, scored by its verification; an image's time is the sum of its
// trials' totals in that file (BOP times the whole image, all objects).
static void write_bop_csvs(const std::vector<pb::TrialRecord>& records, const std::string& dir) {
  std::map<std::string, std::vector<pb::BopResultRow>> files;
  std::map<std::tuple<std::string, int, int>, double> image_time;
  for (const auto& r : records) {
    if (r.status != "ok" || !r.estimate) continue;
    const std::string name = bop_csv_name(r);
    double& t = image_time[{name, r.scene_id, r.im_id}];
    t = r.times && t >= 0 ? t + r.times->total : -1.0;
    pb::BopResultRow row;
    row.scene_id = r.scene_id;
    row.im_id = r.im_id;
    row.obj_id = r.obj_id.value_or(0);
    if (r.instances) {
      for (const auto& inst : *r.instances) {
        row.score = inst.score;
        row.T_cam_model = inst.estimate.pose();
        files[name].push_back(row);
      }
    } else {
      row.score = r.score.value_or(1.0);
      row.T_cam_model = r.estimate->pose();
      files[name].push_back(row);
    }
  }
  if (!files.empty()) fs::create_directories(fs::path(dir) / "bop");
  for (auto& [name, rows] : files) {
    for (auto& row : rows) row.time_s = image_time.at({name, row.scene_id, row.im_id});
    std::stable_sort(rows.begin(), rows.end(), [](const pb::BopResultRow& a, const pb::BopResultRow& b) {
      return std::tie(a.scene_id, a.im_id, a.obj_id) < std::tie(b.scene_id, b.im_id, b.obj_id);
    });
    pb::write_bop_results_csv((fs::path(dir) / "bop" / name).string(), rows);
  }
}

// DIR/plots.json and, through scripts/plot.py, DIR/plots/*.png. Returns the
// exit code (1 when the script fails).
static int write_plots(const pb::Report& rep, const std::string& dir) {
  const std::string data = (fs::path(dir) / "plots.json").string();
  pb::atomic_write_text(data, pb::plots_json(rep).dump(2) + "\n");
  const std::string script = find_plot_script();
  if (script.empty()) throw pb::InputError("scripts/plot.py", "", "plot script not found");
  if (rep.plots.empty()) {
    pb::log_event(pb::LogLevel::info, "no_plot", {{"why", "no swept variable"}});
    return 0;
  }
  const std::string py = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string cmd = py + " '" + script + "' '" + data + "' '" + (fs::path(dir) / "plots").string() + "'";
  if (std::system(cmd.c_str()) != 0) {
    pb::log_event(pb::LogLevel::error, "plot_failed", {{"script", script}, {"hint", "python3-matplotlib missing?"}});
    return 1;
  }
  return 0;
}

// DIR/report.html: the tables, the plots in DIR/plots/ (if any) and the
// gallery, in one self-contained page.
static void write_html(const pb::Report& rep, const std::vector<pb::TrialRecord>& records, const std::string& dir) {
  auto gallery = pb::select_gallery(records);
  pb::draw_gallery(gallery);
  std::vector<pb::HtmlPlot> plots;
  std::error_code ec;
  std::vector<fs::path> pngs;
  for (const auto& e : fs::directory_iterator(fs::path(dir) / "plots", ec))
    if (e.path().extension() == ".png") pngs.push_back(e.path());
  std::sort(pngs.begin(), pngs.end());
  for (const auto& p : pngs) {
    std::ifstream in(p, std::ios::binary);
    plots.push_back({p.stem().string(), std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>())});
  }
  pb::atomic_write_text((fs::path(dir) / "report.html").string(), pb::to_html(rep, gallery, plots));
}

static pb::cli::Command report_cmd("report", "tables (md, csv, tex) and plots from a results folder", [](int argc, char** argv) {
  CLI::App app{"Writes REPORT.{md,csv,tex} into the results folder (thesis values beside each cell) and, "
               "with --plots, PNG plots via scripts/plot.py (matplotlib)."};
  std::string dir, formats = "md,csv,tex";
  pb::ReportOptions opt;
  bool plots = false;
  app.add_option("results", dir, "results folder of `posebench run`")->required();
  app.add_option("--format", formats, "comma-separated: md, csv, tex");
  app.add_flag("--plots", plots, "also write PNG plots");
  pb::cli::add_log_flags(app);
  bool html = false;
  app.add_flag("--html", html, "also write REPORT.html: one self-contained page (tables with intervals, the plots "
                               "of --plots, a gallery of each method's worst failures and some successes)");
  app.add_option("--reference", opt.reference_file, "thesis reference values (YAML)");
  app.add_option("--table", opt.reference_table, "thesis table id to compare with (e.g. 4.1)");
  app.add_option("--plot-x", opt.plot_x, "grid path or added_noise_mm to plot against");
  PB_CLI_PARSE(app, argc, argv);
  if (opt.reference_file.empty()) opt.reference_file = find_reference();

  const nlohmann::json exp = read_experiment_json(dir);
  // Strict: a record with an unknown or missing key is an InputError naming
  // records.jsonl, the line and the key (exit 2, nothing written).
  const auto records = pb::ResultStore::read_records(dir);
  const pb::Report rep = pb::build_report(exp, records, opt);
  write_tables(rep, dir, formats);
  write_bop_csvs(records, dir);
  const int rc = plots ? write_plots(rep, dir) : 0;
  if (html) write_html(rep, records, dir);
  return rc;
});
