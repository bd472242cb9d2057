// The experiment runner: materializes scenes, expands trials, runs them in
// worker processes (crash and timeout isolation), streams records to the
// store, resumes. PCL-free.
#pragma once

#include <string>

#include "runner/experiment.h"

namespace pb {

struct RunOptions {
  std::string out_dir;             // results folder (default results/<name>)
  int jobs = 1;                    // worker processes
  std::string cache_dir = "cache"; // training cache shared by runs ("" = none)
  std::string scenes_dir = "scenes";  // where generated scene sets go
  std::string binary;              // the posebench executable (workers, generator)
  bool quiet = false;              // no progress output
};

struct RunSummary {
  size_t total = 0;        // trials of the experiment
  size_t already_done = 0; // found in the store at start (resume)
  size_t ran = 0;          // run now
  size_t ok = 0, no_hypothesis = 0, errors = 0, timeouts = 0;  // of those run now
  double seconds = 0;
};

// Renders every `generate:` scene source that is not yet materialized (into
// scenes_dir/<name>_<hash8>, by running `posebench generate`) and points its
// `dataset` there. InputError if generation fails.
void prepare_scenes(ExperimentConfig& cfg, const RunOptions& opt);

RunSummary run_experiment(ExperimentConfig cfg, const RunOptions& opt);

// The worker side: reads a context line, then one trial per line on stdin,
// writes one record per line on stdout, until EOF.
int worker_main();

}  // namespace pb
