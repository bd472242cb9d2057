// The lengths a run resolved (issue 9: relative lengths become mm per object
// and sensor): from each record's settings_resolved, per scene set and
// object, every length field (a key ending in _mm of the stage sections,
// and the scale floor) with the smallest and largest value over the group's
// records. PCL-free.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "eval/record.h"

namespace pb {

struct ResolvedLengths {
  std::string group;                                         // "SCENE, obj N"
  std::map<std::string, std::pair<double, double>> range_mm;  // "section.key" -> min, max (mm)
};

// Groups in record order of first appearance; records without
// settings_resolved (failed workers) are skipped. Negative values (the
// "follow another setting" sentinels, e.g. refine.crop_margin_mm -1) are
// left out.
std::vector<ResolvedLengths> resolved_lengths(const std::vector<TrialRecord>& records);

// A Markdown table: a row per length field, a column per group; a range
// "a-b" where the group's records differ. "" when there are no groups.
std::string resolved_lengths_markdown(const std::vector<ResolvedLengths>& groups);

}  // namespace pb
