// Internal interface between the pipeline (pipeline.cpp) and the descriptor
// methods. PCL-free: implementations convert inside their .cpp files.
// Methods are created by name through make_method (registry in
// pipeline.cpp); each descriptor's factory is declared here.
#pragma once

#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "core/types.h"
#include "recognition/cloud.h"

namespace pb {

struct RecognitionSettings;

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
  virtual void train(const std::vector<ViewData>& views, const RecognitionSettings& s) = 0;
  // Binary (de)serialization of the trained state for the on-disk cache.
  virtual void save(std::ostream& out) const = 0;
  virtual void load(std::istream& in) = 0;
  // Online: preprocessed scene (plane removed, normals) -> hypotheses of
  // T_cam_model, best first (Hypothesis::view set). Fills times.describe,
  // match, group, initial_pose. Must be const and thread-safe; random
  // choices draw from `seed`.
  virtual std::vector<Hypothesis> hypothesize(const PointSet& scene, const std::vector<ViewData>& views,
                                              const RecognitionSettings& s, uint64_t seed,
                                              StageTimes& times) const = 0;
};

std::unique_ptr<Method> make_method(const std::string& name);  // InputError for unknown names

std::unique_ptr<Method> make_fpfh_method();
std::unique_ptr<Method> make_shot_method();
std::unique_ptr<Method> make_cvfh_method();
std::unique_ptr<Method> make_esf_method();
std::unique_ptr<Method> make_cesf_method();
std::unique_ptr<Method> make_ourcvfh_method();
std::unique_ptr<Method> make_ppf_method();

}  // namespace pb
