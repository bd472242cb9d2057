// The experiment runner: materializes scenes, expands trials, runs them in
// worker processes (crash and timeout isolation), streams records to the
// store, resumes. PCL-free.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

#include "runner/experiment.h"
#include "runner/shard.h"

namespace pb {

struct RunOptions {
  std::string out_dir;             // results folder (default results/<name>)
  int jobs = 1;                    // worker processes
  std::string cache_dir = "cache"; // training cache shared by runs ("" = none)
  std::string scenes_dir = "scenes";  // where generated scene sets go
  std::string binary;              // the posebench executable (workers, generator)
  bool quiet = false;              // no progress output
  long memory_limit_mb = 0;        // per-trial memory cap (RLIMIT_AS of each worker; 0 = none)
  Shard shard;                     // run only this shard's trials, into OUT/shards/ (runner/shard.h)
};

// What one `posebench run` did: OUT/runs.jsonl gets one line of it per
// invocation that ran trials, `run --json-summary FILE` writes it to FILE.
struct RunSummary {
  std::string started;     // UTC, ISO 8601
  std::string shard;       // "I/N" for a sharded run, "" otherwise
  size_t total = 0;        // trials of the experiment (of this shard, when sharded)
  size_t already_done = 0; // found in the store at start (resume)
  size_t ran = 0;          // run now
  size_t ok = 0, no_hypothesis = 0, errors = 0, timeouts = 0, out_of_memory = 0;  // of those run now
  double seconds = 0;      // wall time of the invocation, scene generation included
  int jobs = 1;            // worker processes
  int omp_threads = 0;     // OMP_NUM_THREADS of each worker (omp_threads_per_worker: the user's, else cores / jobs)
  double load15_end = 0;   // the machine's 15-minute load average at the end (NaN if unknown)
  int host_cores = 0;
};
nlohmann::json summary_json(const RunSummary& s);

// Renders every `generate:` scene source that is not yet materialized (into
// scenes_dir/<name>_<hash8>, by running `posebench generate`) and points its
// `dataset` there. InputError if generation fails. Concurrent runs sharing
// scenes_dir (the shards of a sweep) generate each set once: the first takes
// scenes_dir/<name>_<hash8>.lock and generates, the others wait for it and
// then find the set complete (the generator renames a finished folder into
// place, so a set is never seen half written).
void prepare_scenes(ExperimentConfig& cfg, const RunOptions& opt);

// Runs what is missing. With opt.shard, only that shard's trials, skipping
// any already recorded in OUT (by any shard or a merged run); without, shard
// records found in OUT are merged into OUT/records.jsonl first.
RunSummary run_experiment(ExperimentConfig cfg, const RunOptions& opt);

// The worker side: reads a context line, then one trial per line on stdin,
// writes one record per line on stdout, until EOF.
int worker_main();

}  // namespace pb
