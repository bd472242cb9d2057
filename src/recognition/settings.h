// RecognitionSettings (the struct: recognition_settings.h) read from YAML,
// written as JSON and resolved to mm: one struct per stage, each mirrored
// one to one by a YAML section of the same name (views, preprocess, local, global, ppf,
// refine, verify), plus the descriptor and refinement names, the seed and
// the `scale` section that says what relative lengths refer to.
//
// Lengths scale with the object: every length field may be given in mm
// (`voxel_mm: 10`) or as a fraction of the object's diameter (`voxel_mm:
// 0.05d`), and the default profile is relative (default_relative_lengths()).
// train_model, recognize and refine_from resolve them to mm for their model
// (resolve_lengths) before any stage sees them; records carry the resolved
// values. In code, a length set in mm must also leave `relative`
// (`s.relative.erase("preprocess.voxel_mm")`, or `s.relative.clear()` for
// the stage headers' mm values): resolve_lengths throws std::logic_error for
// a relative field whose number was changed, rather than ignore it. Every
// field is declared once in its stage header, with its comment and its
// `fields` entry, from which parsing, key checks and JSON derive
// (core/settings_fields.h). PCL-free.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/types.h"
#include "core/yaml.h"
#include "recognition/recognition_settings.h"

namespace pb {

// Every relative length in mm: fraction x d x scale.length_factor, d = scale.diameter_mm if > 0
// else model_diameter_mm, but at least scale.min_length_mm. Returns the
// settings with `relative` empty. InputError when a relative length remains
// and d is not positive.
RecognitionSettings resolve_lengths(const RecognitionSettings& s, double model_diameter_mm);

// The sensor's floor for relative lengths: the larger of
// scale.sensor_floor_px pixel footprints (working distance / fx) at the
// working distance (scale.working_distance_mm, else the median valid depth
// of `image`) and scale.sensor_floor_sigmas x the image's depth noise
// (depth_noise_sigma_mm). 0 when there is none (no valid depth, both
// factors 0).
double sensor_length_floor_mm(const ScaleSettings& scale, const DepthImage& image, const Intrinsics& K);

// Whether resolving s's lengths takes the sensor's floor: some length is
// relative and scale.min_length_mm is not given (0).
bool needs_sensor_floor(const RecognitionSettings& s);

// The depth noise of an image (mm, one standard deviation), estimated from
// the image alone: along each row, the second difference
// z[u-1] - 2 z[u] + z[u+1] of three valid pixels cancels a locally linear
// surface and leaves noise of variance 6 sigma^2; differences above 2% of
// the depth (edges, steep surfaces) are left out; sigma = sqrt(mean(d^2) /
// 6). Catches a real sensor's noise and its depth quantization; 0 without
// three valid neighbours in a row. (The plane band of preprocessing uses
// its own, median-based estimate: preprocess/internal.h's depth_noise_sigma.)
double depth_noise_sigma_mm(const DepthImage& image);

// Relative lengths in mm for one image of a scene: the one resolution that
// `posebench run` (and so `advise`) and `recognize` share, so an image gives
// the same settings, trained model and pose in both. d = scale.diameter_mm,
// else `model_diameter_mm` (the models_info diameter, else the extent of the
// training views); the floor = scale.min_length_mm, else the sensor's floor
// (sensor_length_floor_mm) on the scene's first image (`first`, `first_K`),
// so every image of a scene resolves alike and shares one trained model. A
// lone image (a point cloud) is its own first image.
RecognitionSettings resolve_for_scene(const RecognitionSettings& s, double model_diameter_mm, const DepthImage& first,
                                      const Intrinsics& first_K);
// The same with the sensor's floor already measured on the scene's first
// image (sensor_length_floor_mm; read only when needs_sensor_floor(s)): a
// worker measures it once per scene and scale settings.
RecognitionSettings resolve_for_scene(const RecognitionSettings& s, double model_diameter_mm, double sensor_floor_mm);

// Every setting's type, default (relative lengths as "0.05d") and what it
// accepts, section by section: `posebench schema settings`, from which
// scripts/settings_reference.py writes docs/settings.md.
nlohmann::ordered_json recognition_settings_schema();

// The stage sections, in order (and `scale`).
const std::vector<std::string>& recognition_sections();

// Reads the YAML keys descriptor, refinement, seed and the stage sections
// over `base`; unknown keys are errors (file, line, key), except the
// sections named in `other_sections`, which belong to the caller (e.g. the
// runner's `views`) and are skipped here.
RecognitionSettings parse_recognition_settings(const YamlNode& node, RecognitionSettings base = {},
                                               const std::set<std::string>& other_sections = {});
// One setting by its dotted path ("global.top_k", "descriptor"), read from
// `value` over `s` by the same parser and field lists as a YAML section
// (rules, relative lengths "0.05d"): an experiment grid point's override.
// InputError at `value` for an unknown path or a bad value.
RecognitionSettings apply_setting(const RecognitionSettings& s, const std::string& path, const YamlNode& value);

// Every field, in declaration order (trial records).
nlohmann::ordered_json recognition_settings_json(const RecognitionSettings& s);
std::string settings_to_json(const RecognitionSettings& s);

// The fields of `s` that differ from the defaults, section by section, with
// the descriptor and refinement always: the settings a trial record keeps
// and the runner sends its worker, which reads them back over the defaults
// (parse_recognition_settings gives `s` again, relative lengths included).
nlohmann::ordered_json settings_changes_json(const RecognitionSettings& s);

}  // namespace pb
