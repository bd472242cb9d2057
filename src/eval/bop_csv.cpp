#include "eval/bop_csv.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "io/validate.h"

namespace pb {

namespace {

const char* kHeader = "scene_id,im_id,obj_id,score,R,t,time";

std::string fmt(double x) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), x);  // shortest round-trip form
  return std::string(buf, res.ptr);
}

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

double parse_double(const std::string& text, const std::string& path, const std::string& field) {
  const std::string s = trim(text);
  double v = 0;
  const char* end = s.data() + s.size();
  auto res = std::from_chars(s.data(), end, v);
  if (s.empty() || res.ec != std::errc() || res.ptr != end || !std::isfinite(v)) {
    throw InputError(path, field, "'" + s + "' is not a finite number");
  }
  return v;
}

int parse_int(const std::string& text, const std::string& path, const std::string& field) {
  const std::string s = trim(text);
  int v = 0;
  const char* end = s.data() + s.size();
  auto res = std::from_chars(s.data(), end, v);
  if (s.empty() || res.ec != std::errc() || res.ptr != end) {
    throw InputError(path, field, "'" + s + "' is not an integer");
  }
  return v;
}

// The pieces of `s` between the separators (n separators: n + 1 pieces).
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  size_t start = 0;
  for (;;) {
    const size_t at = s.find(sep, start);
    out.push_back(s.substr(start, at == std::string::npos ? std::string::npos : at - start));
    if (at == std::string::npos) return out;
    start = at + 1;
  }
}

std::vector<double> parse_list(const std::string& text, size_t n, const std::string& path,
                               const std::string& field) {
  std::istringstream is(text);
  std::vector<double> v;
  std::string tok;
  while (is >> tok) v.push_back(parse_double(tok, path, field));
  if (v.size() != n) {
    throw InputError(path, field,
                     "expected " + std::to_string(n) + " numbers separated by spaces, got " +
                         std::to_string(v.size()));
  }
  return v;
}

}  // namespace

void write_bop_results_csv(const std::string& path, const std::vector<BopResultRow>& rows) {
  std::map<std::pair<int, int>, double> times;
  std::ostringstream os;
  os << kHeader << '\n';
  for (size_t i = 0; i < rows.size(); ++i) {
    const BopResultRow& r = rows[i];
    const std::string where = "row " + std::to_string(i);
    if (!std::isfinite(r.score)) throw InputError(path, where + " score", "not a finite number");
    if (!std::isfinite(r.time_s)) throw InputError(path, where + " time", "not a finite number");
    if (!r.T_cam_model.R.allFinite() || !r.T_cam_model.t.allFinite()) {
      throw InputError(path, where + " R/t", "the pose has a non-finite element");
    }
    auto [it, inserted] = times.emplace(std::make_pair(r.scene_id, r.im_id), r.time_s);
    if (!inserted && it->second != r.time_s) {
      throw InputError(path, where + " time",
                       "scene " + std::to_string(r.scene_id) + " image " + std::to_string(r.im_id) +
                           " has two different times (" + fmt(it->second) + " and " +
                           fmt(r.time_s) + "); BOP needs one time per image");
    }
    os << r.scene_id << ',' << r.im_id << ',' << r.obj_id << ',' << fmt(r.score) << ',';
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) os << (a + b ? " " : "") << fmt(r.T_cam_model.R(a, b));
    os << ',';
    for (int a = 0; a < 3; ++a) os << (a ? " " : "") << fmt(r.T_cam_model.t(a));
    os << ',' << fmt(r.time_s) << '\n';
  }
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw InputError(path, "", "cannot open " + tmp + " for writing");
    const std::string s = os.str();
    f.write(s.data(), static_cast<std::streamsize>(s.size()));
    f.flush();
    if (!f) {
      std::remove(tmp.c_str());
      throw InputError(path, "", "cannot write " + tmp);
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(path, "", "cannot rename " + tmp + " to the results file");
  }
}

std::vector<BopResultRow> read_bop_results_csv(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(path, "", "cannot open the BOP results file");
  std::vector<BopResultRow> rows;
  std::map<std::pair<int, int>, std::pair<double, int>> times;  // time, line
  std::string line;
  int line_no = 0;
  while (std::getline(f, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line_no == 1 && line.find(kHeader) != std::string::npos) continue;
    if (trim(line).empty()) continue;
    const std::vector<std::string> cols = split(line, ',');
    const std::string L = "line " + std::to_string(line_no);
    if (cols.size() != 7) {
      throw InputError(path, L,
                       "expected 7 comma-separated columns (scene_id,im_id,obj_id,score,R,t,time), got " +
                           std::to_string(cols.size()));
    }
    BopResultRow r;
    r.scene_id = parse_int(cols[0], path, L + " scene_id");
    r.im_id = parse_int(cols[1], path, L + " im_id");
    r.obj_id = parse_int(cols[2], path, L + " obj_id");
    r.score = parse_double(cols[3], path, L + " score");
    const std::vector<double> R = parse_list(cols[4], 9, path, L + " R");
    const std::vector<double> t = parse_list(cols[5], 3, path, L + " t");
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) r.T_cam_model.R(a, b) = R[3 * a + b];
      r.T_cam_model.t(a) = t[a];
    }
    r.time_s = parse_double(cols[6], path, L + " time");
    r.line = line_no;
    if (r.scene_id < 0 || r.im_id < 0 || r.obj_id < 0) {
      throw InputError(path, L + (r.scene_id < 0 ? " scene_id" : r.im_id < 0 ? " im_id" : " obj_id"),
                       "ids are >= 0");
    }
    validate_rotation(r.T_cam_model.R, kResultRotationTolerance, path, L + " R");
    if (r.time_s >= 0) {  // the toolkit: negative = unknown, and times within 1 ms are one time
      auto [it, inserted] = times.emplace(std::make_pair(r.scene_id, r.im_id), std::make_pair(r.time_s, line_no));
      if (!inserted && std::abs(it->second.first - r.time_s) > 1e-3) {
        throw InputError(path, L + " time",
                         "scene " + std::to_string(r.scene_id) + " image " + std::to_string(r.im_id) +
                             " has time " + fmt(r.time_s) + " here but " + fmt(it->second.first) +
                             " on line " + std::to_string(it->second.second) +
                             "; BOP needs one time per image");
      }
    }
    rows.push_back(r);
  }
  if (f.bad()) throw InputError(path, "", "read error");
  return rows;
}

std::string bop_results_filename(const std::string& method, const std::string& dataset,
                                 const std::string& split) {
  std::string m = method;
  for (char& c : m)
    if (c == '_' || c == '.' || std::isspace(static_cast<unsigned char>(c)) || c == '/') c = '-';
  if (m.empty()) throw InputError("", "method", "empty method name");
  auto check = [](const std::string& s, const char* field) {
    if (s.empty()) throw InputError("", field, "must not be empty");
    for (char c : s) {
      if (c == '_' || c == '-' || c == '.' || c == '/' || std::isspace(static_cast<unsigned char>(c))) {
        throw InputError("", field,
                         "'" + s + "' may not contain '_', '-', '.', '/' or spaces (BOP file names)");
      }
    }
  };
  check(dataset, "dataset");
  check(split, "split");
  return m + "_" + dataset + "-" + split + ".csv";
}

std::optional<BopResultsName> parse_bop_results_filename(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
  if (name.size() < 5 || name.compare(name.size() - 4, 4, ".csv") != 0) return std::nullopt;
  name.resize(name.size() - 4);
  const size_t us = name.find('_');
  if (us == std::string::npos || us == 0) return std::nullopt;
  BopResultsName n;
  n.method = name.substr(0, us);
  const std::string rest = name.substr(us + 1);
  if (rest.find('_') != std::string::npos) return std::nullopt;
  const std::vector<std::string> parts = split(rest, '-');  // DATASET-SPLIT[-TYPE...]
  if (parts.size() < 2 || parts[0].empty() || parts[1].empty()) return std::nullopt;
  n.dataset = parts[0];
  n.split = parts[1];
  for (size_t i = 2; i < parts.size(); ++i) n.split_type += (i > 2 ? "_" : "") + parts[i];
  return n;
}

}  // namespace pb
