// `posebench report --html`: one self-contained page per experiment (no
// server, no network: images are inline data URIs) with the report's
// tables (robustness as k of n with its 95% Wilson interval, the thesis's
// value beside each cell), the plots, and the gallery of each method's
// worst failures and a few successes as depth overlays, each with its
// trial's settings and errors below and on hover. A script at the end
// writes "images loaded: K of N" into #pb-status once the page has loaded
// (what the headless-browser test reads).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "report/gallery.h"
#include "report/report.h"

namespace pb {

struct HtmlPlot {
  std::string title;   // e.g. the plot's file stem
  std::string png;     // PNG bytes
};

std::string to_html(const Report& report, const std::map<std::string, std::vector<GalleryItem>>& gallery,
                    const std::vector<HtmlPlot>& plots);

// Standard base64 (RFC 4648, with padding).
std::string base64(const std::string& bytes);

}  // namespace pb
