// BOP results files (bop19 format, ../shared/reference/BOP.md "Results file"):
// CSV with the header `scene_id,im_id,obj_id,score,R,t,time`, R = 9 numbers
// row-major separated by spaces, t = 3 numbers in mm, time = seconds for the
// whole image (the same for every estimate of an image; -1 if unknown). The
// BOP toolkit (scripts/eval_bop19_pose.py) can score the files we write.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

struct BopResultRow {
  int scene_id = 0;
  int im_id = 0;
  int obj_id = 0;
  double score = 1.0;   // confidence of the estimate
  Pose T_cam_model;     // R (row-major in the file) and t (mm)
  double time_s = -1;   // seconds for the whole image; -1 = unknown
  int line = 0;         // read_bop_results_csv: the row's line in the file (1-based)
};

// How far R of a results row may be from a rotation (max |R^T R - I| and
// |det R - 1|): results written with 6 decimals, or from float32, are
// within 1e-5; a matrix that is not a rotation is off by far more.
constexpr double kResultRotationTolerance = 1e-3;

// Writes the rows atomically (PATH.tmp then rename), numbers in their
// shortest form that reads back to the same double. Throws InputError (field
// "time") when two rows of one image have different times (the toolkit
// rejects such files) or a value is not finite, and InputError naming the
// path when it cannot be written.
void write_bop_results_csv(const std::string& path, const std::vector<BopResultRow>& rows);

// Reads a results file (the header line is optional, as in the toolkit).
// Throws InputError naming the file, the line and the field for a missing
// file, a wrong number of columns, a malformed or non-finite number, a
// negative id, an R that is not a rotation (kResultRotationTolerance), or
// two times of one image that differ by more than 1 ms (the toolkit's
// check_consistent_timings; negative times mean unknown and are not
// compared).
std::vector<BopResultRow> read_bop_results_csv(const std::string& path);

// The parts of a results file name, METHOD_DATASET-SPLIT[-SPLITTYPE].csv,
// as bop_toolkit splits it ('_' before the dataset, '-' inside it).
struct BopResultsName {
  std::string method, dataset, split, split_type;  // split_type may be empty
};
// The name's parts, or nothing when the file name (without folders) does
// not follow the convention.
std::optional<BopResultsName> parse_bop_results_filename(const std::string& path);

// The file name the BOP toolkit parses, METHOD_DATASET-SPLIT.csv. '_', '.'
// and spaces in `method` become '-' (the toolkit splits on '_' and '.');
// `dataset` and `split` must be non-empty without '_', '-', '.', '/' or
// spaces (InputError with field "dataset" or "split" otherwise).
std::string bop_results_filename(const std::string& method, const std::string& dataset,
                                 const std::string& split);

}  // namespace pb
