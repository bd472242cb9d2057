// The plot data of a report (what scripts/plot.py draws) and the words on
// its axes and title.
#include <cmath>
#include <regex>

#include "report/report.h"

namespace pb {

std::string plot_axis_label(const std::string& plot_x) {
  if (plot_x == "added_noise_mm") return "added noise sigma (mm)";
  if (plot_x == "global.top_k") return "hypotheses refined (global.top_k)";
  if (plot_x == "ppf.hypotheses") return "hypotheses refined (ppf.hypotheses)";
  return "setting " + plot_x;
}

std::string plot_title(const std::string& experiment, const std::string& plot_x) {
  const std::string what = "robustness and time vs " +
                           std::string(plot_x == "added_noise_mm" ? "added noise" : plot_axis_label(plot_x));
  std::smatch m;
  static const std::regex fig("fig_([0-9]+)_([0-9]+)(?:_(.+))?");
  if (std::regex_match(experiment, m, fig))
    return "Figure " + m[1].str() + "." + m[2].str() + (m[3].matched ? " (" + m[3].str() + ")" : "") + ": " + what;
  return experiment + ": " + what;
}

nlohmann::json plots_json(const Report& r) {
  auto clean = [](const auto& v) {
    nlohmann::json a = nlohmann::json::array();
    for (double x : v) a.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr));
    return a;
  };
  nlohmann::json j = nlohmann::json::array();
  for (const auto& p : r.plots) {
    nlohmann::json pj = {{"name", p.name}, {"x_label", p.x_label}, {"title", p.title}, {"series", nlohmann::json::array()}};
    for (const auto& s : p.series)
      pj["series"].push_back({{"label", s.label}, {"method", s.method}, {"scene", s.scene}, {"x", clean(s.x)},
                              {"robustness", clean(s.robustness)}, {"time", clean(s.time)}, {"correct", s.correct},
                              {"trials", s.trials}});
    j.push_back(pj);
  }
  return j;
}

}  // namespace pb
