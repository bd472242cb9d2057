#include "report/html.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "eval/stats.h"

namespace pb {

namespace {

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string num(double v, const char* f) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

const char* kStyle = R"(body{font-family:sans-serif;margin:1.5em;color:#222}
table{border-collapse:collapse;margin:0.5em 0 1.5em}th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}
th:first-child,th:nth-child(2),td:first-child,td:nth-child(2){text-align:left}.ref{color:#777}.ci{color:#555;font-size:85%}
.gallery{display:flex;flex-wrap:wrap;gap:12px}figure{margin:0;width:330px;border:1px solid #ccc;padding:4px}
figure img{width:320px;display:block}figcaption{font-size:80%;overflow-wrap:anywhere}
.fail{border-color:#c33}.ok{border-color:#3a3}.plot img{max-width:800px})";

// A table cell: robustness as k/n with its interval, others as formatted.
std::string cell_html(const ReportCell& c, const std::string& measure) {
  std::string s;
  if (measure.rfind("robustness", 0) == 0 && c.trials > 0 && std::isfinite(c.value)) {
    const int k = static_cast<int>(std::lround(c.value * c.trials));
    const Proportion p = wilson(k, c.trials);
    s = std::to_string(k) + "/" + std::to_string(c.trials) + " <span class=ci>[" + num(100 * p.lo, "%.0f") + "&ndash;" +
        num(100 * p.hi, "%.0f") + "%]</span>";
  } else {
    s = esc(format_measure(c.value, measure));
  }
  if (std::isfinite(c.reference)) s += " <span class=ref>(" + esc(format_measure(c.reference, measure)) + ")</span>";
  return s;
}

void tables_html(const Report& r, std::ostringstream& o) {
  for (const auto& t : r.tables) {
    o << "<h2>" << esc(t.title) << "</h2>\n";
    if (!t.condition.empty()) o << "<p>Condition: <code>" << esc(t.condition) << "</code></p>\n";
    o << "<table><tr><th>scene set</th><th>measure</th>";
    for (const auto& c : t.columns) o << "<th>" << esc(c) << "</th>";
    o << "</tr>\n";
    for (const auto& row : t.rows) {
      if (row.detail) continue;
      o << "<tr><td>" << esc(row.scenario) << "</td><td>" << esc(measure_label(row.measure)) << "</td>";
      for (const auto& c : row.cells) o << "<td>" << cell_html(c, row.measure) << "</td>";
      o << "</tr>\n";
    }
    o << "</table>\n";
  }
  o << "<p>Robustness: correct of trials, with the 95% Wilson interval; accuracy over correct trials only; "
       "in grey parentheses the thesis's value.</p>\n";
}

std::string caption(const GalleryItem& it) {
  const TrialRecord& r = *it.record;
  std::ostringstream c;
  c << (it.success ? "correct" : "not correct") << " &middot; " << esc(r.scene) << " scene " << r.scene_id << " image "
    << r.im_id << " &middot; status " << esc(r.status);
  if (r.errors)
    c << " &middot; translation " << num(r.errors->translation_mm, "%.1f") << " mm, rotation "
      << num(r.errors->rotation_deg, "%.1f") << "&deg;";
  if (r.added_noise_mm > 0) c << " &middot; added noise " << num(r.added_noise_mm, "%g") << " mm (not drawn)";
  if (!r.params.empty()) c << " &middot; <code>" << esc(r.params.dump()) << "</code>";
  if (r.message) c << " &middot; " << esc(*r.message);
  return c.str();
}

void gallery_html(const std::map<std::string, std::vector<GalleryItem>>& gallery, std::ostringstream& o) {
  o << "<h2>Gallery</h2>\n<p>Per method its worst failures (largest translation error first, then trials "
       "without a pose) and the least accurate successes: the image's depth (near blue, far red), the estimate "
       "in green, the ground truth outlined in magenta. Hover an image for the trial's settings.</p>\n";
  for (const auto& [method, items] : gallery) {
    o << "<h3>" << esc(method) << "</h3>\n<div class=gallery>\n";
    for (const GalleryItem& it : items) {
      const std::string settings = it.record->settings.dump(1);
      o << "<figure class=" << (it.success ? "ok" : "fail") << " title=\"" << esc(it.record->key + "\n" + settings)
        << "\">";
      if (!it.png.empty())
        o << "<img alt=\"" << esc(it.record->key) << "\" src=\"data:image/png;base64," << base64(it.png) << "\">";
      else
        o << "<p>" << esc(it.note) << "</p>";
      o << "<figcaption>" << caption(it) << "<details><summary>settings</summary><pre>" << esc(settings)
        << "</pre></details></figcaption></figure>\n";
    }
    o << "</div>\n";
  }
}

}  // namespace

std::string base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const uint32_t v = (static_cast<uint8_t>(in[i]) << 16) | (static_cast<uint8_t>(in[i + 1]) << 8) |
                       static_cast<uint8_t>(in[i + 2]);
    for (int s = 18; s >= 0; s -= 6) out += k[(v >> s) & 63];
  }
  if (i < in.size()) {
    uint32_t v = static_cast<uint8_t>(in[i]) << 16;
    if (i + 1 < in.size()) v |= static_cast<uint8_t>(in[i + 1]) << 8;
    out += k[(v >> 18) & 63];
    out += k[(v >> 12) & 63];
    out += i + 1 < in.size() ? k[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string to_html(const Report& r, const std::map<std::string, std::vector<GalleryItem>>& gallery,
                    const std::vector<HtmlPlot>& plots) {
  std::ostringstream o;
  o << "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>posebench: " << esc(r.experiment)
    << "</title>\n<style>" << kStyle << "</style></head><body>\n";
  o << "<h1>posebench report: " << esc(r.experiment) << "</h1>\n<p>" << r.records << " records";
  for (const auto& [k, v] : r.status_counts) o << ", " << esc(k) << " " << v;
  o << ".</p>\n";
  tables_html(r, o);
  for (const auto& p : plots)
    o << "<div class=plot><h2>" << esc(p.title) << "</h2><img alt=\"" << esc(p.title)
      << "\" src=\"data:image/png;base64," << base64(p.png) << "\"></div>\n";
  gallery_html(gallery, o);
  o << "<p id=pb-status>images not loaded</p>\n<script>window.addEventListener('load',function(){var n=0,k=0;"
       "for(var i=0;i<document.images.length;i++){n++;var m=document.images[i];if(m.complete&&m.naturalWidth>0)k++;}"
       "document.getElementById('pb-status').textContent='images loaded: '+k+' of '+n;});</script>\n</body></html>\n";
  return o.str();
}

}  // namespace pb
