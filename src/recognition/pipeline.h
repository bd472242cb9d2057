// recognize(scene, model, settings) -> Result: the one call per image that
// every descriptor x refinement combination goes through. PCL-free header.
//
// Stage settings live in their stage headers (preprocess.h, local.h,
// global.h, ppf.h, refine.h, verify.h); each is one struct whose defaults are
// the thesis's values, mirrored one to one by a YAML section of the same
// name (see parse_recognition_settings).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/types.h"
#include "core/yaml.h"
#include "recognition/cloud.h"
#include "recognition/global/global.h"
#include "recognition/local/local.h"
#include "recognition/ppf/ppf.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/refine/refine.h"
#include "recognition/verify/verify.h"
#include "scenes/views.h"

namespace pb {

struct RecognitionSettings {
  std::string descriptor = "fpfh";   // fpfh shot cvfh esf cesf ourcvfh ppf
  std::string refinement = "icp";    // none icp icp_lm icp_plane gicp ndt
  ViewSettings views;                // training views of the model
  PreprocessSettings preprocess;
  LocalSettings local;
  GlobalSettings global;
  PpfSettings ppf;
  RefineSettings refine;
  VerifySettings verify;
  uint64_t seed = 1;                 // seeds every random choice of the call
};

// Reads the YAML sections (descriptor, refinement, views, preprocess, local,
// global, ppf, refine, verify, seed) over `base`; unknown keys are errors.
RecognitionSettings parse_recognition_settings(const YamlNode& node, RecognitionSettings base = {});
// Every field, for the trial records and the cache key.
std::string settings_to_json(const RecognitionSettings& s);

std::vector<std::string> descriptor_names();
std::vector<std::string> refinement_names();

// A model trained for one descriptor: its preprocessed, described training
// views. Opaque; built by train_model, cached on disk.
class TrainedModel;

struct TrainOptions {
  std::string cache_dir;   // "" = no cache; else DIR/<key>.bin, key = hash of
                           // model mesh, views and every training setting
  std::string model_name;  // for messages and the cache key
};
std::shared_ptr<const TrainedModel> train_model(const Mesh& mesh, const RecognitionSettings& s,
                                                const TrainOptions& opt = {},
                                                bool* from_cache = nullptr);

// What a trained model holds (for messages, tests and benchmarks).
struct TrainedModelInfo {
  std::string descriptor;
  std::string model_name;
  int views = 0;            // training views kept (views with too few points are dropped)
  size_t view_points = 0;   // preprocessed points over all views
  bool empty = true;        // nothing to recognize (empty mesh or no view points)
  std::string empty_reason;
  std::string cache_file;   // the cache file read or written ("" = no cache)
};
TrainedModelInfo trained_model_info(const TrainedModel& model);

struct RecognitionResult {
  std::string status = "no_hypothesis";  // "ok" | "no_hypothesis"
  std::string message;                   // why no hypothesis, when so
  std::vector<Hypothesis> hypotheses;    // ranked, best first
  Pose T_cam_model;                      // the chosen pose (valid when ok)
  double score = 0;
  int inliers = 0;
  StageTimes times;
};

// One image: depth + intrinsics + a trained model. Never throws for empty or
// object-free scenes: status says "no_hypothesis" with a message.
RecognitionResult recognize(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                            const RecognitionSettings& s);

}  // namespace pb
