// RecognitionSettings: one struct per stage, each mirrored one to one by a
// YAML section of the same name (views, preprocess, local, global, ppf,
// refine, verify), plus the descriptor and refinement names and the seed. Every
// field is declared once in its stage header, with its comment and its
// `fields` entry, from which parsing, key checks and JSON derive
// (core/settings_fields.h). PCL-free.
#pragma once

#include <nlohmann/json.hpp>

#include <set>
#include <string>
#include <vector>

#include "core/training_views.h"
#include "core/yaml.h"
#include "recognition/global/global.h"
#include "recognition/local/local.h"
#include "recognition/ppf/ppf.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/refine/refine.h"
#include "recognition/verify/verify.h"

namespace pb {

struct RecognitionSettings {
  std::string descriptor = "fpfh";   // fpfh shot cvfh esf cesf ourcvfh ppf (registry.h)
  std::string refinement = "icp";    // none icp icp_lm icp_plane gicp ndt (registry.h)
  ViewSettings views;                // how the caller renders the training views (scenes/views.h);
                                     // training reads the views it is given, not these
  PreprocessSettings preprocess;     // scene and training-view preprocessing
  LocalSettings local;               // fpfh, shot
  GlobalSettings global;             // cvfh, esf, cesf, ourcvfh
  PpfSettings ppf;                   // ppf
  RefineSettings refine;             // every refinement method
  VerifySettings verify;             // inlier counting, acceptance
  uint64_t seed = 1;                 // seeds every random choice of the call
};

// The stage sections, in order.
const std::vector<std::string>& recognition_sections();

// Reads the YAML keys descriptor, refinement, seed and the stage sections
// over `base`; unknown keys are errors (file, line, key), except the
// sections named in `other_sections`, which belong to the caller (e.g. the
// runner's `views`) and are skipped here.
RecognitionSettings parse_recognition_settings(const YamlNode& node, RecognitionSettings base = {},
                                               const std::set<std::string>& other_sections = {});
// Every field, in declaration order (trial records).
nlohmann::ordered_json recognition_settings_json(const RecognitionSettings& s);
std::string settings_to_json(const RecognitionSettings& s);

}  // namespace pb
