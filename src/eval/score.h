// Scoring any tool's BOP results file against a BOP dataset, as the BOP
// toolkit's scripts/eval_bop19_pose.py does (6D localization, bop19
// settings): per test target (scene, image, object, inst_count) the
// inst_count most visible GT instances of the object are the valid ones
// (visib_gt_min = -1), the top inst_count estimates of the object by score
// get their MSSD, MSPD and VSD against every GT of the object, and
// eval/bop_metrics.h's bop_scores matches and counts them.
//
// Differences from the toolkit (as in eval/bop_metrics.h): MSSD and MSPD use
// the model's vertices (models/), not the resampled models_eval/.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "eval/bop_metrics.h"

namespace pb {

struct ScoreSettings {
  std::string dataset;      // BOP dataset root (models/, SPLIT/)
  std::string results;      // the results CSV (METHOD_DATASET-SPLIT.csv)
  // The split folder; empty = from the file name (SPLIT, or SPLIT_TYPE when
  // the name has a split type, as the toolkit's dataset_params builds it).
  std::string split;
  // Test targets file; empty = DATASET/test_targets_bop19.json when present,
  // else every GT instance of every image of the split is a target.
  std::string targets;
  bool vsd = true;          // VSD needs a render per estimate and GT (OSMesa); off = MSSD, MSPD only
  double vsd_delta_mm = 15; // VSD visibility tolerance (bop19: 15 mm; 5 for ITODD)
};

// The errors of one scored estimate against one GT instance.
struct ScoredPair {
  int gt_id = 0;              // index into the image's scene_gt.json list
  double mssd_mm = 0;
  double mspd_px = 0;         // not normalized by the image width
  std::vector<double> vsd;    // per tau (bop19_vsd_taus); empty without VSD
};

// One estimate of the file that was scored (in the top inst_count of its
// target), with its errors against every GT of its object in the image.
struct ScoredEstimate {
  int line = 0;               // line in the results file
  int scene_id = 0, im_id = 0, obj_id = 0;
  double score = 0;
  std::vector<ScoredPair> pairs;
};

struct ScoreResult {
  std::string results, dataset, split;  // what was scored (paths, split folder)
  std::string method;                   // from the file name ("" when it does not follow the convention)
  std::string targets_source;           // the targets file, or "every GT instance of split SPLIT"
  int images = 0;                       // target images
  int rows = 0;                         // estimates in the file
  int rows_scored = 0;                  // estimates that got errors (top inst_count of a target)
  int rows_not_target = 0;              // estimates of an image or object that is no target
  double average_time_s = -1;           // mean over images of the file's time; -1 when any is unknown
  BopScores total;                      // every target
  std::map<int, BopScores> per_object;  // by obj_id
  std::vector<ScoredEstimate> errors;   // every scored estimate, in file order
};

// Reads and checks everything (InputError naming file and field: the
// results file's line and column, the targets file's entry, an image or
// object the dataset lacks), then scores.
ScoreResult score_bop_results(const ScoreSettings& settings);

}  // namespace pb
