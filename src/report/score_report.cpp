#include "report/score_report.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace pb {

namespace {

nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json ar_json(const BopScores& s) {
  return {{"targets", s.targets}, {"ar", num(s.ar)},           {"ar_vsd", num(s.ar_vsd)},
          {"ar_mssd", num(s.ar_mssd)}, {"ar_mspd", num(s.ar_mspd)}};
}

std::string cell(double v) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

}  // namespace

nlohmann::json score_json(const ScoreResult& r) {
  nlohmann::json j;
  j["results"] = r.results;
  j["dataset"] = r.dataset;
  j["split"] = r.split;
  j["method"] = r.method;
  j["targets"] = r.targets_source;
  j["images"] = r.images;
  j["rows"] = r.rows;
  j["rows_scored"] = r.rows_scored;
  j["rows_not_target"] = r.rows_not_target;
  j["targets_count"] = r.total.targets;
  j["bop19_average_recall"] = num(r.total.ar);
  j["bop19_average_recall_vsd"] = num(r.total.ar_vsd);
  j["bop19_average_recall_mssd"] = num(r.total.ar_mssd);
  j["bop19_average_recall_mspd"] = num(r.total.ar_mspd);
  j["bop19_average_time_per_image"] = r.average_time_s;
  j["thresholds"] = {{"vsd", bop19_vsd_thresholds()}, {"vsd_tau", bop19_vsd_taus()},
                     {"mssd", bop19_mssd_thresholds()}, {"mspd", bop19_mspd_thresholds()}};
  j["recall"] = {{"vsd", r.total.recall_vsd}, {"mssd", r.total.recall_mssd}, {"mspd", r.total.recall_mspd}};
  nlohmann::json per = nlohmann::json::object();
  for (const auto& [obj, s] : r.per_object) per[std::to_string(obj)] = ar_json(s);
  j["per_object"] = per;
  nlohmann::json errs = nlohmann::json::array();
  for (const ScoredEstimate& e : r.errors) {
    nlohmann::json gts = nlohmann::json::array();
    for (const ScoredPair& p : e.pairs)
      gts.push_back({{"gt_id", p.gt_id}, {"mssd_mm", p.mssd_mm}, {"mspd_px", p.mspd_px}, {"vsd", p.vsd}});
    errs.push_back({{"line", e.line},   {"scene_id", e.scene_id}, {"im_id", e.im_id},
                    {"obj_id", e.obj_id}, {"score", e.score},       {"gts", gts}});
  }
  j["errors"] = errs;
  return j;
}

std::string score_markdown(const ScoreResult& r) {
  std::ostringstream os;
  os << "# BOP scores of " << r.results << "\n\n";
  os << "Dataset " << r.dataset << ", split " << r.split << "; targets: " << r.targets_source << " ("
     << r.total.targets << " in " << r.images << " images).\n\n";
  os << "| object | targets | AR_VSD | AR_MSSD | AR_MSPD | AR |\n|---|---:|---:|---:|---:|---:|\n";
  auto row = [&](const std::string& name, const BopScores& s) {
    os << "| " << name << " | " << s.targets << " | " << cell(s.ar_vsd) << " | " << cell(s.ar_mssd) << " | "
       << cell(s.ar_mspd) << " | " << cell(s.ar) << " |\n";
  };
  for (const auto& [obj, s] : r.per_object) row(std::to_string(obj), s);
  row("all", r.total);
  os << "\nEstimates: " << r.rows << " in the file, " << r.rows_scored << " scored (the top inst_count of "
     << "each target by score), " << r.rows_not_target << " of no target image or object.\n";
  if (!std::isfinite(r.total.ar_vsd)) os << "VSD not computed: AR is the mean of AR_MSSD and AR_MSPD.\n";
  os << "Average time per image: ";
  if (r.average_time_s < 0)
    os << "unknown (a time is -1).\n";
  else
    os << cell(r.average_time_s) << " s.\n";
  return os.str();
}

}  // namespace pb
