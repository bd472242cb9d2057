// The descriptor methods' interface, between the pipeline (pipeline.cpp,
// training.cpp) and the stage folders local/, global/, ppf/. PCL-free:
// implementations convert inside their .cpp files. A method is built by
// name through the registry (registry.h) with only its own settings section.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/binary_io.h"
#include "core/types.h"
#include "recognition/cloud.h"

namespace pb {

// One preprocessed training view, in its own camera frame.
struct ViewData {
  PointSet cloud;        // preprocessed (voxel grid, normals), view camera frame
  Pose T_cam_model;      // model -> view camera
};

class Method {
 public:
  virtual ~Method() = default;
  virtual std::string name() const = 0;
  // Offline: describe the training views; keep what hypothesize needs.
  // Random choices draw from `seed` (the settings' seed).
  virtual void train(const std::vector<ViewData>& views, uint64_t seed) = 0;
  // The trained state for the on-disk cache; load throws BinaryError (or
  // InputError) on anything it cannot read back exactly.
  virtual void save(BinaryWriter& out) const = 0;
  virtual void load(BinaryReader& in) = 0;
  // Online: preprocessed scene (plane removed, normals) -> hypotheses of
  // T_cam_model, best first (Hypothesis::view set). Must be const and
  // thread-safe; random choices draw from `seed`. A method writes its
  // stages (describe, match, group, initial_pose) as functions and
  // implements this as run_stages (stages.h), which times them into
  // times.describe, match, group and initial_pose.
  virtual std::vector<Hypothesis> hypothesize(const PointSet& scene, const std::vector<ViewData>& views,
                                              uint64_t seed, StageTimes& times) const = 0;
};

struct LocalSettings;
struct GlobalSettings;
struct PpfSettings;

// The factories the registry (registry.cpp) lists; each gets its section.
std::unique_ptr<Method> make_fpfh_method(const LocalSettings& s);
std::unique_ptr<Method> make_shot_method(const LocalSettings& s);
std::unique_ptr<Method> make_cvfh_method(const GlobalSettings& s);
std::unique_ptr<Method> make_esf_method(const GlobalSettings& s);
std::unique_ptr<Method> make_cesf_method(const GlobalSettings& s);
std::unique_ptr<Method> make_ourcvfh_method(const GlobalSettings& s);
std::unique_ptr<Method> make_ppf_method(const PpfSettings& s);

}  // namespace pb
