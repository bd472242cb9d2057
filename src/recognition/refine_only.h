// Registration alone (THESIS.md Table 4.9, Figure 4.12): skip description
// and matching, refine one given initial pose with the configured
// refinement method, and verify it like recognize() does.
#pragma once

#include "recognition/pipeline.h"

namespace pb {

// `init` is T_cam_model. The model view used as the registration source is
// the training view whose viewing direction is closest to the one implied by
// `init`. Status "no_hypothesis" when the scene has no points.
RecognitionResult refine_from(const DepthImage& depth, const Intrinsics& K, const TrainedModel& model,
                              const RecognitionSettings& s, const Pose& init);

}  // namespace pb
