// RecognitionSettings, the struct: one struct per stage, each mirrored one
// to one by a YAML section of the same name, and the default profile of
// relative lengths. Reading, writing and resolving them: settings.h. Apart
// from it so that the registry (registry.cpp), which builds each method
// from its section, needs the struct and not the parser that checks names
// against the registry. PCL-free.
#pragma once

#include <map>
#include <string>

#include "core/training_views.h"
#include "recognition/global/global.h"
#include "recognition/local/local.h"
#include "recognition/ppf/ppf.h"
#include "recognition/preprocess/preprocess.h"
#include "recognition/refine/refine.h"
#include "recognition/verify/verify.h"

namespace pb {

// What relative lengths ("0.05d") refer to, and the floor the sensor sets.
struct ScaleSettings {
  double diameter_mm = 0;          // the diameter d of "0.05d"; 0 = the model's (its models_info
                                   // diameter, or the extent of its training views)
  double min_length_mm = 0;        // no relative length resolves below this (mm); 0 = none, or
                                   // the sensor's floor when the caller knows the sensor
                                   // (sensor_floor_px below)
  double sensor_floor_px = 2.0;    // the sensor's floor: this many pixel footprints at the working
                                   // distance (the runner and `recognize` set min_length_mm from
                                   // it when min_length_mm is 0; 0 = no floor)
  double sensor_floor_sigmas = 2.0; // and this many standard deviations of the depth noise,
                                   // estimated from the image (depth_noise_sigma_mm): the floor
                                   // is the larger of the two; 0 = the pixels alone
  double working_distance_mm = 0;  // where the object is seen (mm); 0 = the median valid depth of
                                   // the scene's first image
  double length_factor = 1.0;      // every relative length x this (one knob for the whole
                                   // profile; `posebench advise` sweeps it)

  template <class S, class F>
  static void fields(S& s, F& f) {
    f("diameter_mm", s.diameter_mm, fields::nonnegative());
    f("min_length_mm", s.min_length_mm, fields::nonnegative());
    f("sensor_floor_px", s.sensor_floor_px, fields::nonnegative());
    f("sensor_floor_sigmas", s.sensor_floor_sigmas, fields::nonnegative());
    f("working_distance_mm", s.working_distance_mm, fields::nonnegative());
    f("length_factor", s.length_factor, fields::positive());
  }
};

// The default profile: "section.field" -> fraction of the diameter. At a
// diameter of 200 mm (the thesis's 10-20 cm objects: the LS5 is 180 mm) it
// gives the values of the stage headers (voxel 10 mm, descriptor radius 60,
// Hough bin 50, ...).
const std::map<std::string, double>& default_relative_lengths();

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
  ScaleSettings scale;               // what relative lengths refer to
  uint64_t seed = 1;                 // seeds every random choice of the call
  // Length fields given relative to the diameter, "section.field" ->
  // fraction; empty once resolved. Their numbers in the sections are
  // placeholders until then.
  std::map<std::string, double> relative = default_relative_lengths();
};

}  // namespace pb
