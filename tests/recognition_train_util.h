// Tests: train a model on a mesh (the training views rendered as the runner
// and the CLI render them, scenes/views.h, then recognition's train_model).
#pragma once

#include <memory>
#include <string>

#include "recognition/pipeline.h"
#include "scenes/views.h"

namespace pb::test {

inline std::shared_ptr<const TrainedModel> train(const Mesh& mesh, const RecognitionSettings& s,
                                                 const TrainOptions& opt = {}, bool* from_cache = nullptr,
                                                 const std::string& name = "model") {
  return train_model(training_views(mesh, s.views, name), s, opt, from_cache);
}

}  // namespace pb::test
