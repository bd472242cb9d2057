// Training views: the model rendered alone from chosen viewpoints (the
// thesis's "model views"). Each view is an organized cloud in its own camera
// frame with the pose T_cam_model that produced it.
#pragma once

#include <string>
#include <vector>

#include "core/training_views.h"
#include "core/types.h"

namespace pb {


// Unit directions from the model origin to each camera (model frame, z up),
// in the order render_training_views uses. InputError on bad settings.
std::vector<Vec3> view_directions(const ViewSettings& settings);

std::vector<TrainingView> render_training_views(const Mesh& mesh, const ViewSettings& settings);

// The training views recognition learns from (train_model): rendered, or
// none with the reason when the mesh is empty or degenerate.
TrainingViews training_views(const Mesh& mesh, const ViewSettings& settings, const std::string& model_name);

}  // namespace pb
