// The trained model (opaque outside recognition): the preprocessed training
// views, the descriptor method's trained state, and the same clouds in the
// model frame for refinement and verification. Private to src/recognition.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/training_views.h"
#include "recognition/method.h"
#include "recognition/settings.h"

namespace pb {

class TrainedModel {
 public:
  std::string model_name;
  std::string descriptor;
  RecognitionSettings settings;          // the settings it was trained with (lengths in mm)
  double diameter_mm = 0;                // what its relative lengths were resolved with
  std::unique_ptr<Method> method;        // null when there is nothing to recognize
  std::string empty_reason;              // why method is null
  std::vector<ViewData> views;           // preprocessed training views (view camera frame)
  std::vector<PointSet> model_frame;     // the same clouds mapped into the model frame
  PointSet merged;                       // every view in the model frame, voxelized (for view -1)
  std::string cache_file;                // where it was read from / written to ("" = none)

  const PointSet& model_cloud(int view) const {
    if (view < 0) return merged;
    if (static_cast<size_t>(view) >= model_frame.size())
      throw std::logic_error("recognition: hypothesis names view " + std::to_string(view) + " of " +
                             std::to_string(model_frame.size()));
    return model_frame[static_cast<size_t>(view)];
  }

  // The cloud verification counts inliers on (VerifySettings::inlier_model).
  const PointSet& verify_cloud(int view, const VerifySettings& v) const {
    return v.inlier_model == "merged" ? merged : model_cloud(view);
  }

  // Fills model_frame and merged from views.
  void derive_model_frame();
};

namespace cache {

// The training cache file of a model: DIR/<model>-<descriptor>-<key>.bin,
// key = FNV-1a 64 of everything training reads (the views as data, the
// preprocess section, the method's own section, the seed). A file that is
// missing, corrupt, of another version or another key is not read (the
// caller rebuilds it).
struct Key {
  std::string text;  // settings part, stored in the file and compared on read
  uint64_t hash = 0; // over text and the view data
};
Key training_key(const TrainingViews& views, const RecognitionSettings& s);
std::string file_name(const std::string& dir, const std::string& model_name, const std::string& descriptor,
                      const Key& key);
bool read(const std::string& path, const Key& key, TrainedModel& m);  // views + method; false = rebuild
void write(const std::string& path, const Key& key, const TrainedModel& m);

}  // namespace cache

}  // namespace pb
