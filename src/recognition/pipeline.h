// The recognition pipeline, top of the data path (PCL-free header):
//   train_model   training views (rendered by the caller, scenes/views.h)
//                 -> preprocess/ -> the descriptor method (local/, global/,
//                 ppf/) -> a trained model, cached on disk;
//   recognize     depth image -> preprocess/ -> method hypotheses -> refine/
//                 -> verify/ -> the best pose;
//   refine_from   registration alone from a given initial pose.
// Methods are selected by name (registry.h); settings.h has one settings
// struct per stage, each mirrored by a YAML section.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/types.h"
#include "recognition/cloud.h"
#include "recognition/settings.h"

namespace pb {

// A model trained for one descriptor: its preprocessed, described training
// views. Opaque; built by train_model.
class TrainedModel;

struct TrainOptions {
  std::string cache_dir;   // "" = no cache; else DIR/<model>-<descriptor>-<key>.bin, key = FNV-1a of the
                           // training views (as data) and the settings training reads
};
// The diameter relative lengths ("0.05d") refer to: views.diameter_mm (the
// mesh's), else the diagonal of the bounding box of every view point in the
// model frame (a model given as a point cloud).
double training_views_diameter(const TrainingViews& views);

// Resolves relative lengths for the model (training_views_diameter) first.
// Never throws for empty input: a model without views is empty (recognize
// then answers no_hypothesis with the reason).
std::shared_ptr<const TrainedModel> train_model(const TrainingViews& views, const RecognitionSettings& s,
                                                const TrainOptions& opt = {}, bool* from_cache = nullptr);

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
  // When ok: the instances found (verify.max_instances), best first; the
  // first is the chosen pose below.
  std::vector<Hypothesis> instances;
  Pose T_cam_model;                      // the chosen pose (valid when ok)
  double score = 0;
  int inliers = 0;
  StageTimes times;
};

// One image: depth + intrinsics + a trained model. Never throws for empty or
// object-free scenes: status says "no_hypothesis" with a message.
RecognitionResult recognize(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                            const RecognitionSettings& s);

// Registration alone (thesis Table 4.9, Figure 4.12): skip description
// and matching, refine `init` (T_cam_model) with the configured refinement
// method, verify and accept it as recognize() does (status no_hypothesis
// when it has no inlier). The model view used as the registration source is
// the training view whose viewing direction is closest to the one `init`
// implies.
RecognitionResult refine_from(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                              const RecognitionSettings& s, const Pose& init);

}  // namespace pb
