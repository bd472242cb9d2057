// posebench run EXPERIMENT.yaml [--out results/NAME] [--jobs N] [--shard I/N]
#include <iostream>

#include "cli/command.h"
#include "io/png.h"
#include "runner/runner.h"

static pb::cli::Command run_cmd("run", "run an experiment (YAML): trials in parallel, resumable", [](int argc, char** argv) {
  CLI::App app{"Runs every trial of an experiment config and streams one JSON record per trial to "
               "OUT/records.jsonl. Interrupted runs resume: only missing trials run."};
  std::string config;
  pb::RunOptions opt;
  opt.jobs = 1;
  app.add_option("config", config, "experiment YAML")->required();
  app.add_option("--out", opt.out_dir, "results folder (default results/NAME)");
  app.add_option("--jobs,-j", opt.jobs, "parallel worker processes")->check(CLI::PositiveNumber);
  app.add_option("--cache", opt.cache_dir, "training cache folder ('' = none)");
  app.add_option("--scenes", opt.scenes_dir, "where generated scene sets go");
  pb::cli::add_log_flags(app, &opt.quiet);
  app.add_option("--memory-limit-mb", opt.memory_limit_mb,
                 "memory cap per trial (the worker's address space, RLIMIT_AS, in MB); a trial over it is "
                 "recorded with status out_of_memory and the sweep goes on")
      ->check(CLI::PositiveNumber);
  std::string shard;
  app.add_option("--shard", shard,
                 "run only shard I of N (0 <= I < N) of the trials, into OUT/shards/I-of-N.*; shards run "
                 "concurrently or one after another on one OUT (also on a shared file system), then "
                 "`posebench merge OUT` gives the records of one run");
  std::string summary_file;
  app.add_option("--json-summary", summary_file,
                 "write what this invocation did as JSON (trials, already recorded, ran, statuses, wall time, "
                 "jobs, load) to FILE; OUT/runs.jsonl keeps one such line per invocation that ran trials");
  PB_CLI_PARSE(app, argc, argv);
  opt.binary = pb::cli::self_path();
  if (app.count("--shard")) opt.shard = pb::parse_shard(shard);
  const pb::ExperimentConfig cfg = pb::load_experiment(config);
  const pb::RunSummary s = pb::run_experiment(cfg, opt);
  const std::string out = opt.out_dir.empty() ? "results/" + cfg.name : opt.out_dir;
  std::cout << "experiment " << cfg.name << " (" << cfg.hash << ")"
            << (opt.shard.active() ? ", shard " + opt.shard.label() : std::string()) << ": " << s.total << " trials, "
            << s.already_done << " already recorded, " << s.ran << " run now (ok " << s.ok << ", no hypothesis "
            << s.no_hypothesis << ", error " << s.errors << ", timeout " << s.timeouts
            << (s.out_of_memory ? ", out of memory " + std::to_string(s.out_of_memory) : std::string()) << ") in " << s.seconds << " s\n";
  if (opt.shard.active())
    std::cout << "records: " << out << "/shards/" << opt.shard.name() << ".records.jsonl (merge with `posebench merge "
              << out << "`)\n";
  else
    std::cout << "records: " << out << "/records.jsonl\n";
  if (!summary_file.empty()) {
    nlohmann::json j = pb::summary_json(s);
    j["experiment"] = cfg.name;
    j["out"] = out;
    pb::atomic_write_text(summary_file, j.dump(2) + "\n");
  }
  return 0;
});

static pb::cli::Command worker_cmd("worker", "(internal) trial worker used by `run`", [](int, char**) {
  return pb::worker_main();
});
