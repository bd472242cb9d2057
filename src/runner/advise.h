// `posebench advise MESH`: which method, refinement and length scale to use
// for one object with one sensor, measured on generated scenes of that
// object. PCL-free.
//
// write_advice_inputs writes, into the output folder, a model registry (the
// user's mesh and three generated distractors sized to it), a table scene
// config (the sensor, the camera 2.5-5 diameters away, inside the sensor's
// range) and an experiment (descriptors x refinements x
// scale.length_factor), which `posebench run` (run_experiment) then runs, so
// the advice is deterministic for a seed and resumable. rank_advice reads
// the records and ranks the cells; best_experiment_yaml writes the winner as
// an experiment of its own with the same scenes, seed and trial keys, so
// `posebench run` on it gives the same records.
#pragma once

#include <string>
#include <vector>

#include "core/types.h"
#include "eval/record.h"
#include "eval/stats.h"

namespace pb {

struct AdviseOptions {
  std::string mesh;                  // the user's mesh (any format assimp reads)
  double mesh_scale = 1.0;           // file units -> mm
  std::string up = "+z";             // the file's up axis
  std::string sensor = "astra";      // synthetic | astra | kinect_one
  std::string scenario = "table";    // the only scenario so far
  int images = 30;                   // generated images
  double budget_ms = 0;              // > 0: cells whose median time per image exceeds it rank last
  uint64_t seed = 1;
  std::vector<std::string> descriptors{"fpfh", "shot", "cvfh", "ourcvfh", "esf", "cesf", "ppf"};
  std::vector<std::string> refinements{"icp", "icp_plane"};
  std::vector<double> length_factors{0.7, 1.0, 1.4};  // scale.length_factor values swept
};

// What write_advice_inputs wrote and what it found about the mesh.
struct AdviceInputs {
  std::string experiment;  // OUT/experiment.yaml
  std::string object;      // the target's registry name (the mesh file's stem)
  double diameter_mm = 0;
  double max_range_mm = 0;     // preprocess.max_range_mm of the experiment
  double translation_mm = 0;   // the translation threshold: a quarter of the diameter
  // preprocess.veil_angle_deg of the experiment: 10 for a time-of-flight
  // sensor (its mixed pixels at depth edges join an object to what stands
  // close before it: results/thesis/FINDINGS.md, "The Kinect One calibrated
  // on real frames"), else 0 (off)
  double veil_angle_deg = 0;
  std::vector<std::string> warnings;  // e.g. the mesh looks symmetric
};
AdviceInputs write_advice_inputs(const AdviseOptions& opt, const std::string& out_dir);

// One cell of the sweep, ranked.
struct AdviceRow {
  std::string descriptor, refinement;
  double length_factor = 1.0;
  Proportion correct;              // k of n with the Wilson 95% interval
  double median_translation_mm = 0;  // over the correct trials (NaN when none)
  double median_rotation_deg = 0;
  double median_time_ms = 0;       // online time per image
  bool within_budget = true;
};
// Ranked: within the budget first, then most correct, then the faster.
std::vector<AdviceRow> rank_advice(const std::vector<TrialRecord>& records, double budget_ms);
std::string advice_table(const std::vector<AdviceRow>& rows, double budget_ms);

// The experiment of `row` alone (OUT/best.yaml), as YAML text.
std::string best_experiment_yaml(const AdviceRow& row, const AdviseOptions& opt, const AdviceInputs& in);

// Symmetry look of a mesh (normalized frame): the rotations about x, y and z
// under which its surface maps onto itself, as a warning text ("" = none
// seen). Surface points are sampled (seeded); a rotation counts when the
// mean distance of other, rotated samples to them is below 1.5 x that of
// the same samples unrotated (the sampling's own spacing) plus tolerance x
// the diameter.
std::string symmetry_warning(const Mesh& mesh, uint64_t seed, double tolerance = 0.005);

}  // namespace pb
