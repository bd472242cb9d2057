// The report's failure gallery: per method (descriptor + refinement), its
// worst failures and a few successes, each drawn as a depth overlay
// (report/overlay.h) of the trial's image with the estimate (green) and
// the ground truth (magenta outline).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "eval/record.h"

namespace pb {

struct GalleryOptions {
  int failures = 3;    // per method: trials not judged correct, the worst first
  int successes = 2;   // per method: correct trials, the least accurate first
};

struct GalleryItem {
  const TrialRecord* record = nullptr;
  bool success = false;
  std::string png;     // the overlay, PNG bytes ("" when it could not be drawn)
  std::string note;    // why there is no image, or "" (e.g. the dataset has moved)
};

// The trials to show, per method ("descriptor+refinement"), without images.
// Failures: not correct; those with an estimate by decreasing translation
// error, then those without one (no hypothesis, error, timeout) in key
// order. Successes: correct, by decreasing translation error (the closest
// calls first). Deterministic: ties keep key order.
std::map<std::string, std::vector<GalleryItem>> select_gallery(const std::vector<TrialRecord>& records,
                                                               const GalleryOptions& opt = {});

// Draws every item's overlay from its record's dataset (the image without
// the trial's added noise, the model mesh, the record's estimate and ground
// truth). An item whose dataset cannot be read keeps no image and says why.
void draw_gallery(std::map<std::string, std::vector<GalleryItem>>& gallery);

}  // namespace pb
